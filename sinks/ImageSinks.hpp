// SPDX-License-Identifier: LGPL-2.1-or-later
// Image outputs: a sequence in a folder laid out as a TUM RGB-D clip (PNG, or EXR when linear), or
// one image file that each frame replaces.   defocus in/ -o out/   defocus photo.png --depth d.png -o out.exr
// Both are written under a hidden temporary name beside the output (.out.partial/, .out.partial.png;
// out/.defocus.partial/ in a folder that exists) and put in place by finish(); abandon() leaves the
// output's name alone (FrameSink.hpp).
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
/// associations.txt listing them (written when the sequence finishes). The frames go into the
/// hidden folder .NAME.partial beside `folder`, which finish() renames to `folder`; when `folder`
/// exists, into FOLDER/.defocus.partial, whose files finish() moves into it.
class ImageSequenceSink final : public FrameSink {
public:
    /// Creates the temporary folder beside `folder` and checks that it is writable; throws
    /// SinkError if not. `linear`: EXR files from CV_32FC3 frames instead of PNG files from
    /// CV_8UC3. `fps` gives the timestamps of frames whose input has none (index / fps).
    ImageSequenceSink(std::filesystem::path folder, bool linear, double fps = 30.0);
    /// Without finish(), abandons the frames (abandon(false)).
    ~ImageSequenceSink() override;

    SinkEncoding encoding() const override;
    /// A frame with no input behind it: frame_NNNNNN, timestamp index / fps, no depth.
    void write(const cv::Mat& image) override;
    void writeFrame(const cv::Mat& image, const Frame& origin) override;
    /// Writes the lists and renames the temporary folder to the output folder. Into a folder that
    /// exists (empty, or holding files with -y), the frames, then the lists, are moved in one by
    /// one; its other files stay. With no frame written, nothing is created (with a warning).
    void finish() override;
    /// Removes the temporary folder, or with `keep` writes its lists and renames it NAME.partial
    /// (replacing an earlier one).
    std::filesystem::path abandon(bool keep) override;
    std::size_t framesWritten() const override { return written_; }
    std::string describe() const override;

private:
    struct Entry {
        double timestamp;
        std::string color; ///< relative to the folder, e.g. "1305031102.175304.png"
        std::string depth; ///< e.g. "depth/1305031102.175304.png"; empty without depth
    };
    std::string nameFor(const Frame& origin);
    void writeLists() const;

    std::filesystem::path folder_; ///< the output, without a trailing '/'
    std::filesystem::path work_;   ///< the hidden folder the frames go to until finish()
    bool linear_;
    double fps_;
    bool finished_ = false;
    std::size_t written_ = 0;
    std::vector<Entry> entries_;
    std::set<std::string> used_;
};

/// Writes every frame to the same hidden temporary file beside `file`, replacing it atomically: the
/// last frame wins, and finish() renames it to `file`. .exr gets linear float, .png/.jpg/.jpeg
/// 8-bit sRGB.
class SingleImageSink final : public FrameSink {
public:
    /// Creates the parent folder if needed and checks that it is writable; throws SinkError for an
    /// unsupported extension or a folder that cannot be written.
    explicit SingleImageSink(std::filesystem::path file);
    /// Without finish(), abandons the image (abandon(false)).
    ~SingleImageSink() override;

    SinkEncoding encoding() const override { return encoding_; }
    void write(const cv::Mat& image) override;
    /// Renames the last frame to `file`; with no frame written, creates nothing.
    void finish() override;
    /// Removes the last frame, or with `keep` renames it NAME.partial.EXT.
    std::filesystem::path abandon(bool keep) override;
    std::size_t framesWritten() const override { return written_; }
    std::string describe() const override;

private:
    std::filesystem::path file_;
    std::filesystem::path work_; ///< the hidden file the frames go to until finish()
    SinkEncoding encoding_;
    std::size_t written_ = 0;
    bool finished_ = false;
};

/// imwrite to a hidden temporary name next to `file`, then rename over it; throws SinkError.
void writeImageAtomically(const std::filesystem::path& file, const cv::Mat& image);

} // namespace defocus
