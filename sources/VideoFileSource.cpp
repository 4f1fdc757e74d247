// SPDX-License-Identifier: LGPL-2.1-or-later
// Video file source: decodes frames with cv::VideoCapture and attaches the optional shared depth.
#include "sources/VideoFileSource.hpp"

#include <cmath>
#include <system_error>
#include <utility>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio/registry.hpp>
#include <spdlog/spdlog.h>

#include "filter/Log.hpp"

#include "sources/ImageIO.hpp"

namespace defocus {

VideoFileSource::VideoFileSource(std::filesystem::path file,
                                 std::optional<std::filesystem::path> depthFile,
                                 double unitsPerMetre)
    : file_(std::move(file)), depthFile_(std::move(depthFile))
{
    std::error_code ec;
    if (depthFile_ && std::filesystem::is_directory(*depthFile_, ec))
        throw SourceError(fmt::format(
            "video '{}': depth '{}' is a folder; a video takes one depth image for all frames",
            file_.string(), depthFile_->string()));
    // FFmpeg directly where it exists: with CAP_ANY a file FFmpeg rejects falls through to the
    // image-sequence backend, whose own error about file name patterns only confuses the log.
    const int api = cv::videoio_registry::hasBackend(cv::CAP_FFMPEG) ? cv::CAP_FFMPEG : cv::CAP_ANY;
    try {
        capture_.open(file_.string(), api);
    } catch (const cv::Exception& e) {
        throw SourceError(fmt::format("cannot open video '{}': {}", file_.string(), e.err));
    }
    if (!capture_.isOpened())
        throw SourceError(fmt::format(
            "cannot open video '{}': no video backend could decode it (corrupt file or missing "
            "codec)",
            file_.string()));
    const double fps = capture_.get(cv::CAP_PROP_FPS);
    frameRate_ = std::isfinite(fps) && fps > 0.0 ? fps : 0.0;
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    if (std::isfinite(count) && count >= 1.0)
        frameCount_ = static_cast<std::size_t>(count);
    // Without depthFile, the depth comes from elsewhere (PairedSource: a folder or depth.txt) or
    // there is none: openSource, which knows which, says so.
    if (depthFile_)
        depth_ = readStoredDepth(*depthFile_, unitsPerMetre);
}

std::optional<Frame> VideoFileSource::next()
{
    if (ended_)
        return std::nullopt;
    cv::Mat image;
    bool read = false;
    try {
        read = capture_.read(image);
    } catch (const cv::Exception& e) {
        throw SourceError(
            fmt::format("video '{}': cannot decode frame {}: {}", file_.string(), next_, e.err));
    }
    if (!read || image.empty()) {
        ended_ = true;
        capture_.release();
        if (frameCount_ && next_ < *frameCount_)
            logger().warn("video '{}': decoding stopped after {} of the {} frames its header states; "
                         "the file is truncated or damaged, and the frames written so far are kept",
                         file_.string(), next_, *frameCount_);
        return std::nullopt;
    }
    Frame frame;
    if (image.type() == CV_8UC3)
        frame.color = image;
    else if (image.type() == CV_8UC1)
        cv::cvtColor(image, frame.color, cv::COLOR_GRAY2BGR);
    else if (image.type() == CV_8UC4)
        cv::cvtColor(image, frame.color, cv::COLOR_BGRA2BGR);
    else
        throw SourceError(fmt::format("video '{}': frame {} has unsupported pixel type {}",
                                      file_.string(), next_, cv::typeToString(image.type())));
    if (!depth_.image.empty()) {
        checkDepthFits(frame.color.size(), fmt::format("{} frame {}", file_.string(), next_),
                       depth_.image.size(), depthFile_->string());
        frame.depth = depth_.image.clone(); // each frame owns its pixels
        frame.depthScale = depth_.unitsPerMetre;
    }
    const double msec = capture_.get(cv::CAP_PROP_POS_MSEC);
    frame.timestampS = std::isfinite(msec) && msec >= 0.0 ? msec / 1000.0
                      : frameRate_ > 0.0                  ? static_cast<double>(next_) / frameRate_
                                                          : 0.0;
    frame.index = next_;
    frame.name = fmt::format("{}#{}", file_.filename().string(), next_);
    ++next_;
    return frame;
}

std::optional<std::size_t> VideoFileSource::frameCount() const
{
    return frameCount_;
}

std::string VideoFileSource::describe() const
{
    return fmt::format("video '{}' ({}{:.3g} fps, {})", file_.string(),
                       frameCount_ ? fmt::format("{} frames, ", *frameCount_) : std::string(),
                       frameRate_,
                       depthFile_ ? fmt::format("depth '{}'", depthFile_->string())
                                  : std::string("no depth"));
}

} // namespace defocus
