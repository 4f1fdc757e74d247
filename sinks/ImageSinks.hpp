// Image outputs: a sequence in a folder laid out as a TUM RGB-D clip (PNG, or EXR when linear), or
// one image file that each frame replaces.   defocus in/ -o out/   defocus photo.png --depth d.png -o out.exr
#pragma once

#include <cstddef>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "sinks/FrameSink.hpp"

namespace defocus {

/// Writes a folder that is again a TUM RGB-D clip: each frame under its input's name (the TUM
/// timestamp, e.g. 1305031102.175304.png; frame_000042.png when the input has no file names),
/// its depth as a 16-bit PNG at 5000 units per metre in depth/, and rgb.txt, depth.txt and
/// associations.txt listing them (written when the sequence finishes). Each file is written under
/// a hidden temporary name and renamed, so the folder never holds a half-written frame.
class ImageSequenceSink final : public FrameSink {
public:
    /// Creates `folder` (and parents) and checks that it is writable; throws SinkError if not.
    /// `linear`: EXR files from CV_32FC3 frames instead of PNG files from CV_8UC3. `fps` gives
    /// the timestamps of frames whose input has none (index / fps).
    ImageSequenceSink(std::filesystem::path folder, bool linear, double fps = 30.0);
    ~ImageSequenceSink() override;

    SinkEncoding encoding() const override;
    /// A frame with no input behind it: frame_NNNNNN, timestamp index / fps, no depth.
    void write(const cv::Mat& image) override;
    void writeFrame(const cv::Mat& image, const Frame& origin) override;
    /// Writes the lists. Frames are complete files as soon as write() returns, so after a failure
    /// in the middle of a clip the earlier frames stay, listed. With no frame written, a folder
    /// that the constructor created is removed again (with a warning), so a failed run leaves no
    /// output.
    void finish() override;
    std::size_t framesWritten() const override { return written_; }
    std::string describe() const override;

    /// Path of the colour image of the `index`th frame written so far.
    std::filesystem::path framePath(std::size_t index) const;

private:
    struct Entry {
        double timestamp;
        std::string color; ///< relative to the folder, e.g. "1305031102.175304.png"
        std::string depth; ///< e.g. "depth/1305031102.175304.png"; empty without depth
    };
    std::string nameFor(const Frame& origin);

    std::filesystem::path folder_;
    bool linear_;
    double fps_;
    bool createdFolder_ = false;
    bool finished_ = false;
    std::size_t written_ = 0;
    std::vector<Entry> entries_;
    std::set<std::string> used_;
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

/// imwrite to a hidden temporary name next to `file`, then rename over it; throws SinkError.
void writeImageAtomically(const std::filesystem::path& file, const cv::Mat& image);

} // namespace defocus
