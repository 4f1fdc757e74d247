// SPDX-License-Identifier: LGPL-2.1-or-later
// V4L2 capture: negotiation (QUERYCAP, ENUM_FMT, S_FMT, S_PARM), mmap streaming with poll(),
// and the conversion of each buffer into a Frame before the buffer goes back to the driver.
#include "sources/V4l2Source.hpp"

#include "sources/V4l2Ioctl.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <span>
#include <system_error>
#include <utility>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "filter/Log.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

using v4l2::errorText;
using v4l2::fieldText;
using v4l2::xioctl;

double monotonicNow()
{
    timespec now{};
    ::clock_gettime(CLOCK_MONOTONIC, &now);
    return static_cast<double>(now.tv_sec) + static_cast<double>(now.tv_nsec) * 1e-9;
}

/// Colour formats in order of preference: uncompressed first (no decoding cost, no JPEG
/// artefacts), MJPEG when an uncompressed format cannot reach the rate, GREY last (no colour).
constexpr std::array<std::uint32_t, 6> colorPreference = {
    V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_NV12, V4L2_PIX_FMT_BGR24,
    V4L2_PIX_FMT_RGB24, V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_GREY};

std::string formatList(const std::vector<std::uint32_t>& formats)
{
    if (formats.empty())
        return "none";
    std::string list;
    for (const std::uint32_t f : formats)
        list += (list.empty() ? "" : ", ") + v4l2::fourccName(f);
    return list;
}

bool contains(const std::vector<std::uint32_t>& formats, std::uint32_t fourcc)
{
    return std::find(formats.begin(), formats.end(), fourcc) != formats.end();
}

} // namespace

bool isCameraPath(const fs::path& path)
{
    if (path.string().starts_with("/dev/video"))
        return true;
    std::error_code ec;
    return fs::is_character_file(path, ec);
}

V4l2Source::V4l2Source(V4l2Options options) : options_(std::move(options))
{
    const std::string& dev = options_.device.string();
    if (options_.width <= 0 || options_.height <= 0)
        throw SourceError(fmt::format("camera {}: size must be positive, got {}x{}", dev,
                                      options_.width, options_.height));
    if (!(options_.fps > 0.0 && std::isfinite(options_.fps)))
        throw SourceError(fmt::format("camera {}: frame rate must be positive, got {}", dev, options_.fps));
    if (!(options_.unitsPerMetre > 0.0 && std::isfinite(options_.unitsPerMetre)))
        throw SourceError(fmt::format("camera {}: depth scale must be a positive number of units "
                                      "per metre, got {}", dev, options_.unitsPerMetre));
    if (!(options_.frameTimeout > 0.0))
        throw SourceError(fmt::format("camera {}: frame timeout must be positive", dev));
    options_.buffers = std::clamp(options_.buffers, 3u, 32u);

    openDevice();
    try {
        checkCapabilities();
        std::vector<std::uint32_t> offered;
        for (__u32 i = 0;; ++i) {
            v4l2_fmtdesc desc{};
            desc.index = i;
            desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
            if (xioctl(fd_, VIDIOC_ENUM_FMT, &desc) != 0)
                break;
            offered.push_back(desc.pixelformat);
        }
        setFormat(chooseFormat(offered), offered);
        setFrameRate();
        startStreaming();
    } catch (...) {
        stopStreaming();
        throw;
    }
    logger().info("{}", describe());
}

V4l2Source::~V4l2Source()
{
    stopStreaming();
}

void V4l2Source::openDevice()
{
    const std::string dev = options_.device.string();
    fd_ = ::open(dev.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) {
        const int error = errno;
        switch (error) {
        case ENOENT:
            throw SourceError(fmt::format("camera {} does not exist (no such V4L2 device; "
                                          "'v4l2-ctl --list-devices' lists the cameras)", dev));
        case EACCES:
        case EPERM:
            throw SourceError(fmt::format("no permission to open camera {} (is the user in the "
                                          "'video' group?)", dev));
        case EBUSY:
            throw DeviceBusy(fmt::format("camera {} is busy (another program is capturing from it)", dev));
        default:
            throw SourceError(fmt::format("cannot open camera {}: {}", dev, errorText(error)));
        }
    }
    struct stat info{};
    if (::fstat(fd_, &info) != 0 || !S_ISCHR(info.st_mode)) {
        ::close(fd_);
        fd_ = -1;
        throw SourceError(fmt::format("{} is not a device node, so not a camera", dev));
    }
}

void V4l2Source::checkCapabilities()
{
    const std::string dev = options_.device.string();
    v4l2_capability cap{};
    if (xioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0)
        throw SourceError(fmt::format("{} is not a V4L2 device (VIDIOC_QUERYCAP: {})", dev,
                                      errorText(errno)));
    card_ = fieldText(cap.card);
    driver_ = fieldText(cap.driver);
    const std::uint32_t caps =
        (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
    if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) {
        if ((caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) != 0)
            throw SourceError(fmt::format("camera {} ({}) uses the multi-planar capture API, which "
                                          "defocus does not read", dev, card_));
        if ((caps & V4L2_CAP_META_CAPTURE) != 0)
            throw SourceError(fmt::format("{} ({}) is a metadata node, not a video node; a camera "
                                          "often has both: try the other one ('v4l2-ctl "
                                          "--list-devices')", dev, card_));
        throw SourceError(fmt::format("{} ({}) is not a video capture device", dev, card_));
    }
    if ((caps & V4L2_CAP_STREAMING) == 0)
        throw SourceError(fmt::format("camera {} ({}) does not support streaming I/O", dev, card_));
}

std::uint32_t V4l2Source::chooseFormat(const std::vector<std::uint32_t>& offered)
{
    const std::string dev = options_.device.string();
    const bool depth = options_.role == V4l2Options::Role::Depth;
    if (!options_.pixelFormat.empty()) {
        const std::uint32_t asked = v4l2::fourccFromName(options_.pixelFormat);
        const bool fits = depth ? v4l2::isDepthFormat(asked) : v4l2::isColorFormat(asked);
        if (!fits)
            throw SourceError(fmt::format(
                "camera {}: pixel format '{}' is not a {} format defocus decodes ({})", dev,
                options_.pixelFormat, depth ? "depth" : "colour",
                depth ? "Z16" : "YUYV, NV12, RGB3, BGR3, GREY, MJPG"));
        if (!contains(offered, asked))
            logger().warn("camera {}: does not list {} (it lists {}); asking for it anyway", dev,
                         v4l2::fourccName(asked), formatList(offered));
        return asked;
    }
    if (depth)
        return V4L2_PIX_FMT_Z16; // asked even when not listed; setFormat() checks the answer

    // The fastest frame interval a format has at the size the driver would pick; unknown when
    // the driver does not enumerate intervals (then the format is assumed to keep up).
    const auto fastestRate = [&](std::uint32_t fourcc) -> std::optional<double> {
        v4l2_frmsizeenum size{};
        size.pixel_format = fourcc;
        __u32 w = static_cast<__u32>(options_.width), h = static_cast<__u32>(options_.height);
        long best = -1;
        for (size.index = 0; xioctl(fd_, VIDIOC_ENUM_FRAMESIZES, &size) == 0; ++size.index) {
            if (size.type != V4L2_FRMSIZE_TYPE_DISCRETE)
                break; // stepwise: the requested size itself is allowed
            const long distance =
                std::labs(static_cast<long>(size.discrete.width) - options_.width) +
                std::labs(static_cast<long>(size.discrete.height) - options_.height);
            if (best < 0 || distance < best) {
                best = distance;
                w = size.discrete.width;
                h = size.discrete.height;
            }
        }
        std::optional<double> fastest;
        v4l2_frmivalenum interval{};
        interval.pixel_format = fourcc;
        interval.width = w;
        interval.height = h;
        for (interval.index = 0; xioctl(fd_, VIDIOC_ENUM_FRAMEINTERVALS, &interval) == 0;
             ++interval.index) {
            const v4l2_fract t = interval.type == V4L2_FRMIVAL_TYPE_DISCRETE
                                     ? interval.discrete
                                     : interval.stepwise.min;
            if (t.numerator > 0)
                fastest = std::max(fastest.value_or(0.0),
                                   static_cast<double>(t.denominator) / t.numerator);
            if (interval.type != V4L2_FRMIVAL_TYPE_DISCRETE)
                break;
        }
        return fastest;
    };

    std::optional<std::uint32_t> fallback;
    double fallbackRate = -1.0;
    for (const std::uint32_t fourcc : colorPreference) {
        if (!contains(offered, fourcc))
            continue;
        const std::optional<double> rate = fastestRate(fourcc);
        if (!rate || *rate >= options_.fps * 0.99)
            return fourcc;
        if (*rate > fallbackRate) {
            fallback = fourcc;
            fallbackRate = *rate;
        }
    }
    if (fallback) {
        logger().warn("camera {}: no format reaches {:.3g} Hz at {}x{}; {} is the fastest at {:.3g} Hz",
                     dev, options_.fps, options_.width, options_.height,
                     v4l2::fourccName(*fallback), fallbackRate);
        return *fallback;
    }
    if (contains(offered, V4L2_PIX_FMT_Z16))
        throw SourceError(fmt::format("camera {} ({}) gives depth only (Z16), no colour; give it as "
                                      "--depth for a colour camera", dev, card_));
    throw SourceError(fmt::format("camera {} ({}) offers no colour format defocus decodes: it "
                                  "lists {}; defocus reads YUYV, NV12, RGB3, BGR3, GREY, MJPG",
                                  dev, card_, formatList(offered)));
}

void V4l2Source::setFormat(std::uint32_t fourcc, const std::vector<std::uint32_t>& offered)
{
    const std::string dev = options_.device.string();
    v4l2_format format{};
    format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    format.fmt.pix.width = static_cast<__u32>(options_.width);
    format.fmt.pix.height = static_cast<__u32>(options_.height);
    format.fmt.pix.pixelformat = fourcc;
    format.fmt.pix.field = V4L2_FIELD_NONE;
    if (xioctl(fd_, VIDIOC_S_FMT, &format) != 0) {
        const int error = errno;
        const std::string message = fmt::format("camera {} ({}): VIDIOC_S_FMT {} {}x{} failed: {}{}", dev, card_,
                                                v4l2::fourccName(fourcc), options_.width, options_.height,
                                                errorText(error),
                                                error == EBUSY ? " (another program is capturing from it)" : "");
        if (error == EBUSY)
            throw DeviceBusy(message);
        throw SourceError(message);
    }
    const v4l2_pix_format& got = format.fmt.pix;
    // Drivers may answer S_FMT with another format without an error (vivid gives YUYV when asked
    // for MJPG or Z16): what was set is what S_FMT returned, not what was asked.
    if (got.pixelformat != fourcc) {
        if (options_.role == V4l2Options::Role::Depth)
            throw SourceError(fmt::format(
                "camera {} ({}) is not a depth camera: asked for Z16 depth, the driver gave {} "
                "(it lists {})", dev, card_, v4l2::fourccName(got.pixelformat), formatList(offered)));
        if (!v4l2::isColorFormat(got.pixelformat))
            throw SourceError(fmt::format("camera {} ({}): asked for {}, the driver gave {}, which "
                                          "defocus does not decode", dev, card_,
                                          v4l2::fourccName(fourcc), v4l2::fourccName(got.pixelformat)));
        logger().warn("camera {}: asked for {}, the driver gave {}; reading {}", dev,
                     v4l2::fourccName(fourcc), v4l2::fourccName(got.pixelformat),
                     v4l2::fourccName(got.pixelformat));
    }
    if (got.width == 0 || got.height == 0 || got.width > 16384 || got.height > 16384)
        throw SourceError(fmt::format("camera {}: the driver set an unusable size {}x{}", dev,
                                      got.width, got.height));
    if (got.width != static_cast<__u32>(options_.width) || got.height != static_cast<__u32>(options_.height))
        logger().info("camera {}: asked for {}x{}, the driver gives {}x{}", dev, options_.width,
                     options_.height, got.width, got.height);
    if (got.field != V4L2_FIELD_NONE && got.field != V4L2_FIELD_ANY)
        logger().warn("camera {}: the driver delivers interlaced frames (field order {}); they are "
                     "read as progressive", dev, got.field);
    layout_ = {got.pixelformat, static_cast<int>(got.width), static_cast<int>(got.height),
               got.bytesperline};
    if (got.pixelformat != V4L2_PIX_FMT_MJPEG) {
        // A stride narrower than a packed row is a driver bug; read packed rows instead.
        v4l2::PixelLayout packed = layout_;
        packed.bytesPerLine = 0;
        if (layout_.bytesPerLine < v4l2::strideOf(packed))
            layout_.bytesPerLine = 0;
    }
    const bool yuv = got.pixelformat == V4L2_PIX_FMT_YUYV || got.pixelformat == V4L2_PIX_FMT_NV12;
    // The extended fields count only where the driver says it filled them.
    const bool extended = got.priv == V4L2_PIX_FMT_PRIV_MAGIC;
    const v4l2::YuvEncoding encoding =
        v4l2::yuvEncoding(got.colorspace, extended ? got.ycbcr_enc : std::uint32_t{V4L2_YCBCR_ENC_DEFAULT},
                          extended ? got.quantization : std::uint32_t{V4L2_QUANTIZATION_DEFAULT});
    layout_.matrix = encoding.matrix;
    layout_.range = encoding.range;
    // Kept as captured (yuvColor), the planes go to the filter with the driver's matrix and range;
    // made BGR here, they are read as BT.601 limited range.
    const bool bt601Limited = encoding.matrix == YuvImage::Matrix::Bt601 && encoding.range == YuvImage::Range::Limited;
    if (yuv && (!encoding.supported || (!options_.yuvColor && !bt601Limited)))
        logger().warn("camera {}: the driver encodes {} with colorspace {}, Y'CbCr encoding {} and quantization {}; "
                     "defocus reads {}, so colours will be slightly off", dev, v4l2::fourccName(got.pixelformat),
                     got.colorspace, got.ycbcr_enc, got.quantization,
                     encoding.supported ? "BT.601 limited range" : "BT.601 in its place");
}

void V4l2Source::setFrameRate()
{
    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    bool set = false;
    if (xioctl(fd_, VIDIOC_G_PARM, &parm) == 0 &&
        (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME) != 0) {
        // Frame interval as a fraction of a second: 1000 / (1000 fps) keeps 0.001 Hz resolution.
        parm.parm.capture.timeperframe.numerator = 1000;
        parm.parm.capture.timeperframe.denominator =
            static_cast<__u32>(std::lround(options_.fps * 1000.0));
        set = xioctl(fd_, VIDIOC_S_PARM, &parm) == 0;
        if (!set)
            logger().warn("camera {}: VIDIOC_S_PARM failed ({}); capturing at the driver's rate",
                         options_.device.string(), errorText(errno));
        // S_PARM returns the interval the driver set; read it again in case it did not.
        if (xioctl(fd_, VIDIOC_G_PARM, &parm) != 0)
            parm.parm.capture.timeperframe = {};
    } else {
        logger().info("camera {}: the driver does not set frame rates; capturing at its own rate",
                     options_.device.string());
    }
    const v4l2_fract t = parm.parm.capture.timeperframe;
    frameRate_ = t.numerator > 0 && t.denominator > 0
                     ? static_cast<double>(t.denominator) / t.numerator
                     : options_.fps;
    if (set && std::abs(frameRate_ - options_.fps) > 0.01 * options_.fps)
        logger().info("camera {}: asked for {:.3g} Hz, the driver gives {:.3g} Hz",
                     options_.device.string(), options_.fps, frameRate_);
}

void V4l2Source::startStreaming()
{
    const std::string dev = options_.device.string();
    v4l2_requestbuffers request{};
    request.count = options_.buffers;
    request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    request.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd_, VIDIOC_REQBUFS, &request) != 0)
        throw SourceError(fmt::format("camera {} ({}): VIDIOC_REQBUFS for {} mmap buffers failed: {}",
                                      dev, card_, options_.buffers, errorText(errno)));
    if (request.count < 2)
        throw SourceError(fmt::format("camera {} ({}): the driver gave {} buffer(s); streaming "
                                      "needs at least 2", dev, card_, request.count));
    if (request.count < 3)
        logger().warn("camera {}: the driver gave only {} buffers; frames may be dropped", dev,
                     request.count);
    for (__u32 i = 0; i < request.count; ++i) {
        v4l2_buffer buffer{};
        buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buffer.memory = V4L2_MEMORY_MMAP;
        buffer.index = i;
        if (xioctl(fd_, VIDIOC_QUERYBUF, &buffer) != 0)
            throw SourceError(fmt::format("camera {}: VIDIOC_QUERYBUF {} failed: {}", dev, i,
                                          errorText(errno)));
        void* start = ::mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_,
                             static_cast<off_t>(buffer.m.offset));
        if (start == MAP_FAILED)
            throw SourceError(fmt::format("camera {}: mmap of buffer {} ({} bytes) failed: {}", dev,
                                          i, buffer.length, errorText(errno)));
        buffers_.push_back({start, buffer.length});
        if (layout_.fourcc != V4L2_PIX_FMT_MJPEG && buffer.length < v4l2::minimumFrameBytes(layout_))
            throw SourceError(fmt::format("camera {}: buffer {} holds {} bytes, a {}x{} {} frame "
                                          "needs {}", dev, i, buffer.length, layout_.width,
                                          layout_.height, v4l2::fourccName(layout_.fourcc),
                                          v4l2::minimumFrameBytes(layout_)));
        if (xioctl(fd_, VIDIOC_QBUF, &buffer) != 0)
            throw SourceError(fmt::format("camera {}: VIDIOC_QBUF {} failed: {}", dev, i,
                                          errorText(errno)));
    }
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(fd_, VIDIOC_STREAMON, &type) != 0)
        throw SourceError(fmt::format("camera {} ({}): VIDIOC_STREAMON failed: {}", dev, card_,
                                      errorText(errno)));
    streaming_ = true;
}

void V4l2Source::stopStreaming() noexcept
{
    if (fd_ < 0)
        return;
    if (streaming_) {
        v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        xioctl(fd_, VIDIOC_STREAMOFF, &type); // fails with ENODEV once unplugged; nothing to do
        streaming_ = false;
    }
    for (const Buffer& buffer : buffers_)
        ::munmap(buffer.start, buffer.length);
    buffers_.clear();
    ::close(fd_);
    fd_ = -1;
}

void V4l2Source::throwDisconnected(const std::string& what, int error) const
{
    throw SourceError(fmt::format("camera {} disconnected after {} frames ({}: {})",
                                  options_.device.string(), delivered_, what, errorText(error)));
}

bool V4l2Source::dequeue(std::optional<Frame>& frame)
{
    const std::string dev = options_.device.string();
    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd_, VIDIOC_DQBUF, &buffer) != 0) {
        const int error = errno;
        if (error == EAGAIN)
            return false;
        if (error == ENODEV || error == EIO)
            throwDisconnected("VIDIOC_DQBUF", error);
        throw SourceError(fmt::format("camera {}: VIDIOC_DQBUF failed after {} frames: {}", dev,
                                      delivered_, errorText(error)));
    }
    const double now = monotonicNow();
    if (buffer.index >= buffers_.size())
        throw SourceError(fmt::format("camera {}: the driver returned buffer {} of {}", dev,
                                      buffer.index, buffers_.size()));
    if (lastSequence_ && buffer.sequence > *lastSequence_ + 1)
        dropped_ += buffer.sequence - *lastSequence_ - 1;
    lastSequence_ = buffer.sequence;

    cv::Mat image;
    std::optional<YuvImage> yuv;
    std::string problem;
    if ((buffer.flags & V4L2_BUF_FLAG_ERROR) != 0) {
        problem = "the driver marked it as damaged";
    } else {
        const Buffer& mapped = buffers_[buffer.index];
        // Some drivers leave bytesused at 0 for fixed-size formats: then the buffer is full.
        const std::size_t used = std::min<std::size_t>(
            buffer.bytesused != 0 ? buffer.bytesused : mapped.length, mapped.length);
        const std::span<const std::uint8_t> bytes(static_cast<const std::uint8_t*>(mapped.start), used);
        if (layout_.fourcc != V4L2_PIX_FMT_MJPEG && used < v4l2::minimumFrameBytes(layout_))
            problem = fmt::format("{} bytes, a frame needs {}", used, v4l2::minimumFrameBytes(layout_));
        else if (!(options_.yuvColor && options_.role == V4l2Options::Role::Color &&
                   (yuv = v4l2::capturedYuv(bytes, layout_))))
            image = v4l2::convert(bytes, layout_);
        if (!yuv && image.empty() && problem.empty())
            problem = fmt::format("its {} data do not decode", v4l2::fourccName(layout_.fourcc));
    }
    // The converted image (or the copied planes) owns its pixels, so the buffer goes back to the
    // driver at once.
    if (xioctl(fd_, VIDIOC_QBUF, &buffer) != 0) {
        const int error = errno;
        if (error == ENODEV || error == EIO)
            throwDisconnected("VIDIOC_QBUF", error);
        throw SourceError(fmt::format("camera {}: VIDIOC_QBUF failed after {} frames: {}", dev,
                                      delivered_, errorText(error)));
    }
    if (!yuv && image.empty()) {
        ++dropped_;
        if (warnings_++ < 5)
            logger().warn("camera {}: skipped frame {}: {}", dev, buffer.sequence, problem);
        return true;
    }

    // The driver's capture time, on CLOCK_MONOTONIC, when it says so; drivers that do not say
    // which clock (v4l2loopback) are believed when their time lies within the last second of
    // the monotonic clock; otherwise the dequeue time stands in.
    const double driverTime = static_cast<double>(buffer.timestamp.tv_sec) +
                              static_cast<double>(buffer.timestamp.tv_usec) * 1e-6;
    const std::uint32_t clock = buffer.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK;
    const bool believable =
        driverTime > 0.0 &&
        (clock == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC ||
         (clock == V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN && driverTime <= now + 1e-3 && driverTime > now - 1.0));

    frame.emplace();
    if (options_.role == V4l2Options::Role::Depth) {
        frame->depth = std::move(image);
        frame->depthScale = options_.unitsPerMetre;
    } else if (yuv)
        frame->yuv = std::move(*yuv);
    else
        frame->color = std::move(image);
    frame->timestampS = believable ? driverTime : now;
    frame->index = delivered_++;
    frame->name = fmt::format("{}#{}", options_.device.filename().string(), frame->index);
    return true;
}

std::optional<Frame> V4l2Source::nextWithin(std::chrono::milliseconds timeout)
{
    using Clock = std::chrono::steady_clock;
    const Clock::time_point deadline = Clock::now() + timeout;
    for (;;) {
        const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
        pollfd poller{fd_, POLLIN, 0};
        const int ready = ::poll(&poller, 1, static_cast<int>(std::max<long long>(0, left.count())));
        if (ready < 0) {
            if (errno == EINTR)
                continue;
            throw SourceError(fmt::format("camera {}: poll failed: {}", options_.device.string(),
                                          errorText(errno)));
        }
        if (ready == 0)
            return std::nullopt;
        // DQBUF tells a frame, an unplugged device (ENODEV, EIO) and a stream error apart.
        std::optional<Frame> frame;
        const bool dequeued = dequeue(frame);
        if (frame)
            return frame;
        if (!dequeued && (poller.revents & (POLLHUP | POLLNVAL)) != 0)
            throwDisconnected("poll", ENODEV);
        if (!dequeued && (poller.revents & POLLERR) != 0)
            throw SourceError(fmt::format("camera {}: the driver reports a stream error after {} "
                                          "frames", options_.device.string(), delivered_));
        if (Clock::now() >= deadline)
            return std::nullopt;
    }
}

std::optional<Frame> V4l2Source::next()
{
    const auto timeout = std::chrono::milliseconds(std::llround(options_.frameTimeout * 1000.0));
    if (std::optional<Frame> frame = nextWithin(timeout))
        return frame;
    throw SourceError(fmt::format("camera {} ({}) delivered no frame for {:.3g} s (after {} frames)",
                                  options_.device.string(), card_, options_.frameTimeout, delivered_));
}

std::string V4l2Source::describe() const
{
    return fmt::format("camera {} ('{}', {}: {} {}x{} at {:.3g} Hz, {} buffers, {})",
                       options_.device.string(), card_, driver_, v4l2::fourccName(layout_.fourcc),
                       layout_.width, layout_.height, frameRate_, buffers_.size(),
                       options_.role == V4l2Options::Role::Depth ? "depth" : "colour");
}

} // namespace defocus
