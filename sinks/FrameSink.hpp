// SPDX-License-Identifier: LGPL-2.1-or-later
// The one contract every output implements: frames in display order, then finish().
//   -o out/        image sequence in the TUM layout: the input's frame names, rgb.txt, depth/
//                  depth.txt and associations.txt (PNG, or EXR when the output is linear HDR)
//   -o out.mp4     video (.mp4 H.264, .mkv FFV1, .webm VP9, .avi) through cv::VideoWriter
//   -o out.png     a single frame (the last one written wins; defocus refuses a clip of several
//                  frames); -o out.exr the same, linear float
//   -o /dev/video10  a virtual camera (v4l2loopback), YUYV
// An output that exists is refused (SinkError) unless SinkOptions::overwrite, and so is one whose
// folder is missing (a folder output's own last folder is made). A file output is
// written under a hidden temporary name beside its final one (.NAME.partial.EXT; a folder's into
// .NAME.partial/, or NAME/.defocus.partial/ when the folder exists) and put in place by finish()
// only: a run that fails or is stopped calls abandon() instead, so nothing of it stands under the
// final name and an earlier output there stays; abandon(true) keeps what was written under
// NAME.partial.EXT (NAME.partial/).
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <opencv2/core.hpp>

#include "defocus/Frame.hpp"

namespace defocus {

/// Thrown when an output cannot be created or written; the message names the file.
class SinkError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// What a sink wants from the pipeline.
enum class SinkEncoding {
    Srgb8,    ///< CV_8UC3 BGR, sRGB-encoded
    Linear32F ///< CV_32FC3 BGR, scene-linear, unclipped
};

class FrameSink {
public:
    virtual ~FrameSink() = default;
    virtual SinkEncoding encoding() const = 0;
    /// Writes one frame (in the encoding above). Throws SinkError on failure.
    virtual void write(const cv::Mat& image) = 0;
    /// The same, with the input frame it was made from: sinks that keep the input's frame names
    /// and timestamps (image sequences) use it; the others write the image alone.
    virtual void writeFrame(const cv::Mat& image, const Frame& origin)
    {
        (void)origin;
        write(image);
    }
    /// The run is done: finalises the output (closes the video container, writes a folder's
    /// lists) and puts it under its final name. Idempotent.
    virtual void finish() = 0;
    /// The run failed or was stopped: nothing is put under the final name (whatever stood there
    /// before stays). What was written is removed, or with `keep` finalised under
    /// partialPath(output), which is returned (empty when nothing was kept: no frame written, or
    /// not `keep`). Then finish() and abandon() do nothing. A file sink destroyed without
    /// finish() abandons its output. This default, for outputs without a name (a window, a
    /// virtual camera), is finish().
    virtual std::filesystem::path abandon(bool keep)
    {
        (void)keep;
        finish();
        return {};
    }
    /// Frames written so far.
    virtual std::size_t framesWritten() const = 0;
    /// One line for logs, e.g. "video 'out.mp4' (mp4v, 30 fps, 120 frames)".
    virtual std::string describe() const = 0;
};

struct SinkOptions {
    SinkOptions() = default;
    SinkOptions(std::filesystem::path outputPath, double frameRate = 30.0, bool linear = false)
        : output(std::move(outputPath)), fps(frameRate), linearSequence(linear)
    {
    }

    std::filesystem::path output;
    /// Frame rate for video containers, Hz.
    double fps = 30.0;
    /// For -o DIR/: write EXR (linear float) instead of PNG (8-bit sRGB).
    bool linearSequence = false;
    /// Replace an output that exists (-y/--overwrite); without it, an existing file or a folder
    /// that is not empty is refused with a SinkError naming it.
    bool overwrite = false;
    /// Video codec: "" = the container's default (.mp4 h264, .mkv ffv1, .webm vp9, .avi mjpg),
    /// or one of h264, mp4v, ffv1, vp9, mjpg.
    std::string codec;
    /// For -o DIR/: frames encoded at once, on threads of the sink's own (>= 1; 1 = each frame
    /// written in the call that gives it). Other outputs are written one frame after the other.
    std::size_t threads = 1;
};

/// Picks the sink from the output path: a trailing '/' or an existing directory -> sequence;
/// .mp4/.mkv/.webm/.avi -> video; .png/.jpg -> single 8-bit frame; .exr -> single linear frame;
/// /dev/video* -> a V4L2 output device (V4l2OutputSink.hpp; an existing device is never refused).
/// Throws SinkError for an unknown extension, an output that exists without `overwrite`, or a
/// file that cannot be created.
std::unique_ptr<FrameSink> openSink(const SinkOptions& options);

/// Throws SinkError "output 'FILE' exists (-y overwrites it)" when `file` exists (for a folder:
/// holds anything) and `overwrite` is false. For outputs besides the main one (contact sheet,
/// timings JSON), checked before any frame is processed.
void refuseExisting(const std::filesystem::path& file, bool overwrite);

/// Throws SinkError "cannot write 'FILE': folder 'DIR' does not exist" when the folder an output
/// goes into is missing. A folder output (`isFolder`) may be missing itself, as its sink makes that
/// last folder; never a whole path, which a typo would create.
void requireParentFolder(const std::filesystem::path& output, bool isFolder);
/// Where abandon(true) keeps an unfinished output: out.mp4 -> out.partial.mp4; a `folder` output
/// out/ (or out) -> out.partial.
std::filesystem::path partialPath(const std::filesystem::path& output, bool folder = false);
/// The hidden temporary name a file sink writes `output` under until finish() renames it:
/// out.mp4 -> .out.partial.mp4, a folder out/ -> .out.partial (in the same folder as the final
/// name, so that the rename is atomic).
std::filesystem::path temporaryPath(const std::filesystem::path& output, bool folder = false);
/// A file sink's abandon(keep) of what it wrote under `temporary` (`written` frames): removes it,
/// or with `keep` and a frame written renames it to partialPath(output, folder), replacing an
/// earlier one, and returns that (else an empty path). A file that cannot be kept is removed; a
/// folder's frames stay where they are. Throws SinkError "cannot keep the partial WHAT '...'".
std::filesystem::path keepOrRemove(const std::filesystem::path& temporary, const std::filesystem::path& output,
                                   bool folder, bool keep, std::size_t written, std::string_view what);

/// Writes `contents` to `file` under a temporary name in the same folder and renames it into
/// place, so no reader ever sees a half-written file. Throws SinkError naming the file.
void writeFileAtomically(const std::filesystem::path& file, const std::string& contents);

} // namespace defocus
