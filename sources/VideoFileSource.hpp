// SPDX-License-Identifier: LGPL-2.1-or-later
// A video file decoded by cv::VideoCapture: colour only, with an optional single depth image
// applied to every frame.   defocus clip.mp4 --depth depth.png -o out.mp4
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include <opencv2/videoio.hpp>

#include "sources/FrameSource.hpp"
#include "sources/ImageIO.hpp"

namespace defocus {

class VideoFileSource final : public FrameSource {
public:
    /// Opens the container at once (SourceError naming the file when no backend decodes it).
    /// `depthFile`: one depth image for every frame (a static camera), or none: frames come
    /// without depth (a PairedSource adds a depth folder's or depth.txt's; alone, they pass
    /// through in focus).
    VideoFileSource(std::filesystem::path file, std::optional<std::filesystem::path> depthFile,
                    double unitsPerMetre);

    /// Throws SourceError when a frame cannot be decoded or the depth has another aspect ratio.
    /// A stream that ends before the frame count the container states (a truncated file) ends
    /// with a warning naming both counts: the frames decoded so far are processed and kept.
    std::optional<Frame> next() override;
    /// The container's frame count, when it states one (it may be an estimate).
    std::optional<std::size_t> frameCount() const override;
    double frameRate() const override { return frameRate_; }
    std::string describe() const override;

private:
    std::filesystem::path file_;
    std::optional<std::filesystem::path> depthFile_;
    cv::VideoCapture capture_;
    StoredDepth depth_;
    double frameRate_ = 0.0;
    std::optional<std::size_t> frameCount_;
    std::size_t next_ = 0;
    bool ended_ = false;
};

} // namespace defocus
