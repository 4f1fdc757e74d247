// SPDX-License-Identifier: LGPL-2.1-or-later
// Video output through cv::VideoWriter (FFmpeg): .mp4 as H.264 (avc1, plays in browsers), .mkv
// as lossless FFV1, .webm as VP9, .avi as Motion JPEG; --codec h264|mp4v|ffv1|vp9|mjpg picks
// another.   defocus data/tum_fr1_rpy -o out.mp4      defocus in/ -o out.mkv (lossless)
// OpenCV 4.6 passes no quality or bit-rate setting to these encoders (VIDEOWRITER_PROP_QUALITY
// is read by its MJPEG writer only), so there is none here: each codec runs at FFmpeg's default.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include <opencv2/videoio.hpp>

#include "sinks/FrameSink.hpp"

namespace defocus {

class VideoSink final : public FrameSink {
public:
    /// Picks the codec (`codec` by name, or the container's default) and proves at once that it
    /// opens (a tiny probe file, deleted again), so that a missing encoder or an unwritable folder
    /// fails before any frame is processed. Frames go to .NAME.partial.EXT beside `file`, renamed
    /// to `file` by finish(). Throws SinkError naming the file and the codecs tried.
    VideoSink(std::filesystem::path file, double fps, const std::string& codec = {});
    /// Without finish(), abandons the file (abandon(false)).
    ~VideoSink() override;
    VideoSink(const VideoSink&) = delete;
    VideoSink& operator=(const VideoSink&) = delete;

    SinkEncoding encoding() const override { return SinkEncoding::Srgb8; }
    /// The first frame fixes the size; a frame of another size throws SinkError.
    void write(const cv::Mat& image) override;
    /// Closes the container and renames it into place. With no frame written, the temporary
    /// file is deleted and no file is created.
    void finish() override;
    /// Closes the container; deletes it, or with `keep` renames it to NAME.partial.EXT (a
    /// playable, shorter video).
    std::filesystem::path abandon(bool keep) override;
    std::size_t framesWritten() const override { return written_; }
    std::string describe() const override;

    /// FourCC in use, e.g. "avc1".
    const std::string& codec() const { return codec_; }

private:
    /// `probe`: the constructor trying a codec; what FFmpeg says of one that does not open goes to
    /// the debug log, not standard error (the constructor's error says it).
    bool openWriter(cv::VideoWriter& writer, const std::string& fourcc, cv::Size size, bool probe = false) const;

    std::filesystem::path file_;
    std::filesystem::path partial_;
    double fps_;
    std::string codec_;     ///< FourCC, e.g. "avc1"
    std::string codecName_; ///< --codec name, e.g. "h264"
    cv::VideoWriter writer_;
    cv::Size size_;
    std::size_t written_ = 0;
    bool finished_ = false;
};

} // namespace defocus
