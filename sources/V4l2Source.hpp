// SPDX-License-Identifier: LGPL-2.1-or-later
// A V4L2 camera read with the raw V4L2 API: mmap streaming, the driver's timestamps, colour
// (YUYV, NV12, RGB3, BGR3, GREY, MJPG) or Z16 depth.
//   defocus /dev/video0 --depth depth.png -o out.mp4 --frames 300
//   defocus /dev/video0 --depth /dev/video2 -o out.mp4     (colour + Z16 depth node, by timestamp)
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "sources/FrameSource.hpp"
#include "sources/V4l2Formats.hpp"

namespace defocus {

struct V4l2Options {
    /// What the node is read for: colour frames (Frame::color) or Z16 depth (Frame::depth).
    enum class Role { Color, Depth };

    /// The device node, e.g. /dev/video0.
    std::filesystem::path device;
    Role role = Role::Color;
    /// Capture size asked of the driver, pixels (> 0). The driver picks the nearest size it has;
    /// size() tells which.
    int width = 640;
    int height = 480;
    /// Frame rate asked of the driver with VIDIOC_S_PARM, Hz (> 0); frameRate() tells what it set.
    double fps = 30.0;
    /// Pixel format to ask for by fourcc ("MJPG", "NV12", "Z16"); empty: the first the node lists
    /// of YUYV, NV12, BGR3, RGB3, MJPG, GREY that reaches `fps` at the size (colour), Z16 (depth).
    std::string pixelFormat;
    /// Colour in YUYV or NV12 comes as it was captured (Frame::yuv, Frame::color empty) for the
    /// filter to upload as it is; other formats, and colour when this is false, come as BGR.
    bool yuvColor = false;
    /// Units per metre of Z16 depth (> 0); RealSense and most depth cameras give millimetres.
    double unitsPerMetre = 1000.0;
    /// mmap buffers to ask for, 3..32: one with the driver filling it, one being converted, one
    /// spare so a slow frame does not make the driver drop the next.
    unsigned buffers = 4;
    /// Longest wait for a frame before next() gives up with SourceError, seconds (> 0).
    double frameTimeout = 5.0;
};

class V4l2Source final : public FrameSource {
public:
    /// Opens the node and starts streaming: QUERYCAP (a single-planar capture device with
    /// streaming I/O), ENUM_FMT, S_FMT (checking the format, size and stride the driver gave
    /// back), S_PARM, REQBUFS/QUERYBUF/mmap/QBUF, STREAMON. Throws SourceError naming the node
    /// and what is wrong: missing, no permission, busy, not a capture node, no usable format,
    /// a depth node that substitutes another format for Z16.
    explicit V4l2Source(V4l2Options options);
    ~V4l2Source() override;
    V4l2Source(const V4l2Source&) = delete;
    V4l2Source& operator=(const V4l2Source&) = delete;

    /// The next frame (waits up to frameTimeout). Frames the driver marks as bad or that do not
    /// decode are skipped and counted in droppedFrames(). Never ends by itself: throws
    /// SourceError "camera /dev/video0 disconnected after N frames" when the device goes away
    /// (ENODEV or EIO, e.g. unplugged), or when no frame comes within frameTimeout.
    std::optional<Frame> next() override;
    /// A frame if one is ready within `timeout` (0: only one already captured), nullopt if not;
    /// the stream goes on. Throws like next() when the device goes away.
    std::optional<Frame> nextWithin(std::chrono::milliseconds timeout);

    bool isLive() const override { return true; }
    /// The rate the driver reports after S_PARM, Hz; the requested one when it reports none.
    double frameRate() const override { return frameRate_; }
    std::string describe() const override;

    /// The format and size the driver actually delivers.
    const v4l2::PixelLayout& layout() const { return layout_; }
    std::uint32_t pixelFormat() const { return layout_.fourcc; }
    cv::Size size() const { return {layout_.width, layout_.height}; }
    const std::filesystem::path& device() const { return options_.device; }
    /// Frames delivered so far by next() and nextWithin().
    std::size_t framesDelivered() const { return delivered_; }
    /// Frames lost: gaps in the driver's sequence numbers (the driver had no free buffer) plus
    /// frames skipped as bad or undecodable.
    std::size_t droppedFrames() const { return dropped_; }

private:
    struct Buffer {
        void* start = nullptr;
        std::size_t length = 0;
    };

    void openDevice();
    void checkCapabilities();
    std::uint32_t chooseFormat(const std::vector<std::uint32_t>& offered);
    void setFormat(std::uint32_t fourcc, const std::vector<std::uint32_t>& offered);
    void setFrameRate();
    void startStreaming();
    void stopStreaming() noexcept;
    /// Dequeues, converts and requeues one buffer into `frame` (left empty for a skipped frame);
    /// false when no buffer was ready.
    bool dequeue(std::optional<Frame>& frame);
    [[noreturn]] void throwDisconnected(const std::string& what, int error) const;

    V4l2Options options_;
    int fd_ = -1;
    std::string card_;
    std::string driver_;
    v4l2::PixelLayout layout_;
    double frameRate_ = 0.0;
    std::vector<Buffer> buffers_;
    bool streaming_ = false;
    std::size_t delivered_ = 0;
    std::size_t dropped_ = 0;
    std::optional<std::uint32_t> lastSequence_;
    std::size_t warnings_ = 0;
};

/// True for paths that name a V4L2 node: /dev/video* (whether or not it exists), or any
/// character device.
bool isCameraPath(const std::filesystem::path& path);

} // namespace defocus
