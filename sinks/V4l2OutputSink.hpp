// SPDX-License-Identifier: LGPL-2.1-or-later
// A virtual camera: frames written to a V4L2 output device (v4l2loopback), as YUYV 4:2:2 in
// BT.601 limited range, so that any program that reads a webcam sees the filtered stream.
//   sudo modprobe v4l2loopback video_nr=10 card_label=defocus exclusive_caps=1
//   defocus /dev/video0 --depth depth.png -o /dev/video10
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "sinks/FrameSink.hpp"

namespace defocus {

/// True for paths the V4L2 output sink takes: /dev/video* (and symbolic links to them, such as
/// /dev/v4l/by-id/... or /dev/v4l/by-path/...).
bool isV4l2DevicePath(const std::filesystem::path& path);

/// BGR CV_8UC3 (sRGB-encoded, as the filter writes it) to YUYV 4:2:2 bytes (Y0 U Y1 V), BT.601
/// limited range: Y = 16 + 219 (0.299 R + 0.587 G + 0.114 B) / 255, U and V = 128 + 224 (B - Y')
/// / (1.772 * 255) and 128 + 224 (R - Y') / (1.402 * 255) with Y' unscaled luma, each of a pair
/// of pixels' mean colour (chroma sited between the two). Every value is the exact one rounded
/// to the nearest integer. `image` needs an even width; `out` receives width * height * 2 bytes,
/// rows packed.
void encodeYuyv601(const cv::Mat& image, std::vector<std::uint8_t>& out);

/// The virtual camera. Writes with write() on a non-blocking descriptor, never waits for a
/// reader: a frame the driver cannot take at once (EAGAIN) is dropped and counted, as the
/// preview drops frames it cannot show.
class V4l2OutputSink final : public FrameSink {
public:
    /// Opens `device` and checks it is a video output device that takes write(); the format is
    /// set by the first frame (its size). Throws SinkError naming the device and what it is.
    V4l2OutputSink(std::filesystem::path device, double fps);
    ~V4l2OutputSink() override;
    V4l2OutputSink(const V4l2OutputSink&) = delete;
    V4l2OutputSink& operator=(const V4l2OutputSink&) = delete;

    SinkEncoding encoding() const override { return SinkEncoding::Srgb8; }
    /// The first frame sets the device's format (YUYV, its size, BT.601 limited range) and rate;
    /// a frame of another size, an odd width or a driver that changes the format throw SinkError.
    void write(const cv::Mat& image) override;
    /// Closes the device; readers keep the last frame (v4l2loopback). Idempotent.
    void finish() override;
    /// Frames the driver took.
    std::size_t framesWritten() const override { return written_; }
    /// Frames the driver could not take at once (EAGAIN), dropped.
    std::size_t framesDropped() const { return dropped_; }
    std::string describe() const override;

private:
    void setFormat(cv::Size size);

    std::filesystem::path device_;
    double fps_;
    int fd_ = -1;
    std::string card_;
    std::string driver_;
    cv::Size size_;
    std::vector<std::uint8_t> buffer_;
    std::size_t written_ = 0;
    std::size_t dropped_ = 0;
};

} // namespace defocus
