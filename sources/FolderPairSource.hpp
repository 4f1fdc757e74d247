// SPDX-License-Identifier: LGPL-2.1-or-later
// A folder of colour images, optionally paired with a folder of depth images by sorted file name.
//   defocus rgb_dir/ --depth depth_dir/ -o out/
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "sources/FrameSource.hpp"
#include "sources/ImageIO.hpp"

namespace defocus {

class FolderPairSource final : public FrameSource {
public:
    /// Lists the images (png, jpg, jpeg, exr, tif, tiff, bmp, webp; hidden files skipped) of both
    /// folders in natural name order ("f2" before "f10") and pairs them one to one. `depth`: a
    /// folder with as many images as `colorFolder`, a single depth image used for every frame,
    /// or none (frames pass through in focus). `unitsPerMetre`: scale of 16-bit depth images.
    /// Throws SourceError for an empty folder or unequal counts (naming both folders and counts),
    /// and from next() for an unreadable image or a depth of another aspect ratio than its colour.
    FolderPairSource(std::filesystem::path colorFolder, std::optional<std::filesystem::path> depth,
                     double unitsPerMetre);

    std::optional<Frame> next() override;
    /// Each pair's files read and decoded on the thread that runs the read.
    std::optional<Read> nextRead() override;
    std::optional<std::size_t> frameCount() const override;
    std::string describe() const override;

private:
    std::filesystem::path colorFolder_;
    std::optional<std::filesystem::path> depth_;
    double unitsPerMetre_;
    std::vector<std::filesystem::path> colorFiles_;
    std::vector<std::filesystem::path> depthFiles_; // empty unless depth_ is a folder
    StoredDepth sharedDepth_;                       // set when depth_ is a single file
    std::size_t next_ = 0;
};

} // namespace defocus
