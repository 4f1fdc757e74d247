// Image outputs: a numbered sequence in a folder (PNG, or EXR when linear), or one image file that
// each frame replaces.   defocus in/ -o out/      defocus photo.png --depth d.png -o out.exr
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "sinks/FrameSink.hpp"

namespace defocus {

/// Writes frame_000000.png, frame_000001.png, ... (or .exr) into a folder. Each file is written
/// under a hidden temporary name and renamed, so the folder never holds a half-written frame.
class ImageSequenceSink final : public FrameSink {
public:
    /// Creates `folder` (and parents) and checks that it is writable; throws SinkError if not.
    /// `linear`: EXR files from CV_32FC3 frames instead of PNG files from CV_8UC3.
    ImageSequenceSink(std::filesystem::path folder, bool linear);

    SinkEncoding encoding() const override;
    void write(const cv::Mat& image) override;
    /// Frames are complete files as soon as write() returns, so after a failure in the middle of
    /// a clip the earlier frames stay as they are. With no frame written, a folder that the
    /// constructor created is removed again (with a warning), so a failed run leaves no output.
    void finish() override;
    std::size_t framesWritten() const override { return written_; }
    std::string describe() const override;

    /// Path of frame `index`, e.g. folder/frame_000042.png.
    std::filesystem::path framePath(std::size_t index) const;

private:
    std::filesystem::path folder_;
    bool linear_;
    bool createdFolder_ = false;
    bool finished_ = false;
    std::size_t written_ = 0;
};

/// Writes every frame to the same file, replacing it atomically (temporary file + rename): the
/// last frame wins. .exr gets linear float, .png/.jpg/.jpeg 8-bit sRGB.
class SingleImageSink final : public FrameSink {
public:
    /// Creates the parent folder if needed and checks that it is writable; throws SinkError for an
    /// unsupported extension or a folder that cannot be written.
    explicit SingleImageSink(std::filesystem::path file);

    SinkEncoding encoding() const override { return encoding_; }
    void write(const cv::Mat& image) override;
    void finish() override {}
    std::size_t framesWritten() const override { return written_; }
    std::string describe() const override;

private:
    std::filesystem::path file_;
    SinkEncoding encoding_;
    std::size_t written_ = 0;
};

} // namespace defocus
