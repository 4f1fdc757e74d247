// SPDX-License-Identifier: LGPL-2.1-or-later
// The virtual camera: QUERYCAP (video output with write()), S_FMT YUYV + S_PARM on the first
// frame, then one non-blocking write() per frame of BT.601 YUYV.
#include "sinks/V4l2OutputSink.hpp"

#include "sources/V4l2Ioctl.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <system_error>
#include <utility>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
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

std::uint8_t rounded(double value)
{
    return static_cast<std::uint8_t>(std::lround(value)); // in [16, 240] for inputs in [0, 255]
}

} // namespace

bool isV4l2DevicePath(const fs::path& path)
{
    const std::string text = path.string();
    if (text.rfind("/dev/video", 0) == 0 || text.rfind("/dev/v4l/", 0) == 0)
        return true;
    std::error_code ec;
    const fs::path target = fs::canonical(path, ec);
    return !ec && target.string().rfind("/dev/video", 0) == 0;
}

void encodeYuyv601(const cv::Mat& image, std::vector<std::uint8_t>& out)
{
    CV_Assert(image.type() == CV_8UC3 && image.cols % 2 == 0);
    out.resize(static_cast<std::size_t>(image.cols) * static_cast<std::size_t>(image.rows) * 2);
    // BT.601: Kr = 0.299, Kb = 0.114; luma scaled to 219 codes over 16, chroma to 224 around 128.
    constexpr double kr = 0.299, kb = 0.114, kg = 1.0 - kr - kb;
    constexpr double ys = 219.0 / 255.0, cs = 224.0 / 255.0;
    std::uint8_t* o = out.data();
    for (int y = 0; y < image.rows; ++y) {
        const auto* row = image.ptr<cv::Vec3b>(y);
        for (int x = 0; x < image.cols; x += 2, o += 4) {
            const cv::Vec3b p0 = row[x], p1 = row[x + 1];
            const double l0 = kr * p0[2] + kg * p0[1] + kb * p0[0];
            const double l1 = kr * p1[2] + kg * p1[1] + kb * p1[0];
            const double r = 0.5 * (p0[2] + p1[2]), b = 0.5 * (p0[0] + p1[0]);
            const double l = 0.5 * (l0 + l1);
            o[0] = rounded(16.0 + ys * l0);
            o[1] = rounded(128.0 + cs * (b - l) / (2.0 * (1.0 - kb)));
            o[2] = rounded(16.0 + ys * l1);
            o[3] = rounded(128.0 + cs * (r - l) / (2.0 * (1.0 - kr)));
        }
    }
}

V4l2OutputSink::V4l2OutputSink(fs::path device, double fps) : device_(std::move(device)), fps_(fps)
{
    const std::string dev = device_.string();
    fd_ = ::open(dev.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) {
        const int error = errno;
        if (error == ENOENT)
            throw SinkError(fmt::format("virtual camera {} does not exist (load v4l2loopback: 'sudo modprobe "
                                        "v4l2loopback video_nr=N exclusive_caps=1', see docs/v4l2.md)",
                                        dev));
        throw SinkError(fmt::format("cannot open virtual camera {}: {}", dev, errorText(error)));
    }
    struct stat info{};
    v4l2_capability cap{};
    if (::fstat(fd_, &info) != 0 || !S_ISCHR(info.st_mode) || xioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0) {
        ::close(fd_);
        fd_ = -1;
        throw SinkError(fmt::format("{} is not a V4L2 device, so it cannot be a virtual camera", dev));
    }
    card_ = fieldText(cap.card);
    driver_ = fieldText(cap.driver);
    const std::uint32_t caps =
        (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
    std::string problem;
    if ((caps & V4L2_CAP_VIDEO_OUTPUT) == 0)
        problem = fmt::format("{} ({}) is not a video output device (a camera? a virtual camera is a "
                              "v4l2loopback node, see docs/v4l2.md)", dev, card_);
    else if ((caps & V4L2_CAP_READWRITE) == 0)
        problem = fmt::format("video output {} ({}) does not take write(), which defocus uses", dev, card_);
    if (!problem.empty()) {
        ::close(fd_);
        fd_ = -1;
        throw SinkError(problem);
    }
}

V4l2OutputSink::~V4l2OutputSink()
{
    finish();
}

void V4l2OutputSink::setFormat(cv::Size size)
{
    const std::string dev = device_.string();
    if (size.width % 2 != 0)
        throw SinkError(fmt::format("virtual camera {}: YUYV needs an even width, the frames are {}x{}", dev,
                                    size.width, size.height));
    v4l2_format format{};
    format.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    auto& pix = format.fmt.pix;
    pix.width = static_cast<std::uint32_t>(size.width);
    pix.height = static_cast<std::uint32_t>(size.height);
    pix.pixelformat = V4L2_PIX_FMT_YUYV;
    pix.field = V4L2_FIELD_NONE;
    pix.bytesperline = pix.width * 2;
    pix.sizeimage = pix.bytesperline * pix.height;
    pix.colorspace = V4L2_COLORSPACE_SMPTE170M; // BT.601 primaries and matrix
    pix.ycbcr_enc = V4L2_YCBCR_ENC_601;
    pix.quantization = V4L2_QUANTIZATION_LIM_RANGE;
    pix.xfer_func = V4L2_XFER_FUNC_SRGB;
    if (xioctl(fd_, VIDIOC_S_FMT, &format) != 0)
        throw SinkError(fmt::format("virtual camera {} ({}) refuses YUYV {}x{} (VIDIOC_S_FMT: {}); a reader "
                                    "may hold another format",
                                    dev, card_, size.width, size.height, errorText(errno)));
    if (pix.pixelformat != V4L2_PIX_FMT_YUYV || pix.width != static_cast<std::uint32_t>(size.width) ||
        pix.height != static_cast<std::uint32_t>(size.height) ||
        (pix.bytesperline != 0 && pix.bytesperline != static_cast<std::uint32_t>(size.width) * 2))
        throw SinkError(fmt::format("virtual camera {} ({}) was asked for YUYV {}x{} and answered {} {}x{} "
                                    "({} bytes per line); a reader may hold another format",
                                    dev, card_, size.width, size.height,
                                    std::string(reinterpret_cast<const char*>(&pix.pixelformat), 4), pix.width,
                                    pix.height, pix.bytesperline));
    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    parm.parm.output.timeperframe.numerator = 1000;
    parm.parm.output.timeperframe.denominator = static_cast<std::uint32_t>(std::lround(fps_ * 1000.0));
    if (xioctl(fd_, VIDIOC_S_PARM, &parm) != 0)
        logger().debug("virtual camera {}: VIDIOC_S_PARM {:.3g} fps: {}", dev, fps_, errorText(errno));
    size_ = size;
}

void V4l2OutputSink::write(const cv::Mat& image)
{
    if (fd_ < 0)
        throw SinkError(fmt::format("virtual camera {} is closed", device_.string()));
    CV_Assert(image.type() == CV_8UC3);
    if (size_.empty())
        setFormat(image.size());
    else if (image.size() != size_)
        throw SinkError(fmt::format("virtual camera {}: frame of {}x{} after frames of {}x{}",
                                    device_.string(), image.cols, image.rows, size_.width, size_.height));
    encodeYuyv601(image, buffer_);
    ssize_t n = 0;
    do
        n = ::write(fd_, buffer_.data(), buffer_.size());
    while (n < 0 && errno == EINTR);
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        ++dropped_;
        return;
    }
    if (n < 0)
        throw SinkError(fmt::format("virtual camera {}: write: {}", device_.string(), errorText(errno)));
    if (static_cast<std::size_t>(n) != buffer_.size())
        throw SinkError(fmt::format("virtual camera {} took {} of a frame's {} bytes", device_.string(), n,
                                    buffer_.size()));
    ++written_;
}

void V4l2OutputSink::finish()
{
    if (fd_ >= 0) {
        ::close(fd_);
        fd_ = -1;
    }
}

std::string V4l2OutputSink::describe() const
{
    return fmt::format("virtual camera {} ({}, {}; YUYV {}x{}, {:.3g} fps, {} frames, {} dropped)",
                       device_.string(), card_, driver_, size_.width, size_.height, fps_, written_, dropped_);
}

} // namespace defocus
