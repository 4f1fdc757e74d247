// The one contract every output implements: frames in display order, then finish().
//   -o out/        numbered PNG sequence (EXR when the output is linear HDR)
//   -o out.mp4     video (.mp4, .mkv, .avi) through cv::VideoWriter
//   -o out.png     a single frame (the last one written wins); -o out.exr the same, linear float
//   -o /dev/video10  a virtual camera (v4l2loopback), YUYV
#pragma once

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include <opencv2/core.hpp>

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
    /// Finalises the output (closes the video container). Idempotent; also run by the destructor.
    virtual void finish() = 0;
    /// Frames written so far.
    virtual std::size_t framesWritten() const = 0;
    /// One line for logs, e.g. "video 'out.mp4' (mp4v, 30 fps, 120 frames)".
    virtual std::string describe() const = 0;
};

struct SinkOptions {
    std::filesystem::path output;
    /// Frame rate for video containers, Hz.
    double fps = 30.0;
    /// For -o DIR/: write EXR (linear float) instead of PNG (8-bit sRGB).
    bool linearSequence = false;
};

/// Picks the sink from the output path: a trailing '/' or an existing directory -> sequence;
/// .mp4/.mkv/.avi -> video; .png/.jpg -> single 8-bit frame; .exr -> single linear frame;
/// /dev/video* -> a V4L2 output device (V4l2OutputSink.hpp).
/// Throws SinkError for an unknown extension or a file that cannot be created.
std::unique_ptr<FrameSink> openSink(const SinkOptions& options);

} // namespace defocus
