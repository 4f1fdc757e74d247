// SPDX-License-Identifier: LGPL-2.1-or-later
// V4L2 pixel format conversions: OpenCV's colour conversions on a Mat header laid over the
// capture buffer, so each frame is read once and written once.
#include "sources/V4l2Formats.hpp"

#include <array>
#include <bit>

#include <linux/videodev2.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace defocus::v4l2 {
namespace {

/// Bytes per pixel of the first plane of the packed formats; 0 for MJPEG.
std::size_t bytesPerPixel(std::uint32_t fourcc)
{
    switch (fourcc) {
    case V4L2_PIX_FMT_YUYV:
    case V4L2_PIX_FMT_Z16:
        return 2;
    case V4L2_PIX_FMT_RGB24:
    case V4L2_PIX_FMT_BGR24:
        return 3;
    case V4L2_PIX_FMT_NV12:
    case V4L2_PIX_FMT_GREY:
        return 1;
    default:
        return 0;
    }
}

/// A Mat header over `rows` rows of `data` at `stride`, or an empty Mat when `data` is too
/// short. Never written through: the conversions below only read it.
cv::Mat view(std::span<const std::uint8_t> data, int rows, int cols, int type, std::size_t stride)
{
    if (rows <= 0 || cols <= 0 || stride < static_cast<std::size_t>(cols) * CV_ELEM_SIZE(type) ||
        data.size() < stride * static_cast<std::size_t>(rows))
        return {};
    return cv::Mat(rows, cols, type, const_cast<std::uint8_t*>(data.data()), stride);
}

std::size_t strideFor(int width, std::size_t bytesPerLine, std::size_t pixelBytes)
{
    return bytesPerLine != 0 ? bytesPerLine : static_cast<std::size_t>(width) * pixelBytes;
}

} // namespace

std::string fourccName(std::uint32_t fourcc)
{
    std::string name(4, '?');
    for (std::size_t i = 0; i < 4; ++i) {
        const auto c = static_cast<char>((fourcc >> (8 * i)) & 0xFFu);
        if (c >= 0x20 && c < 0x7F)
            name[i] = c;
    }
    return name;
}

std::uint32_t fourccFromName(std::string_view name)
{
    if (name.empty() || name.size() > 4)
        return 0;
    std::uint32_t code = 0;
    for (std::size_t i = 0; i < 4; ++i) {
        const auto c = static_cast<unsigned char>(i < name.size() ? name[i] : ' ');
        code |= static_cast<std::uint32_t>(c) << (8 * i);
    }
    return code;
}

bool isColorFormat(std::uint32_t fourcc)
{
    static constexpr std::array<std::uint32_t, 6> formats = {
        V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_NV12, V4L2_PIX_FMT_RGB24,
        V4L2_PIX_FMT_BGR24, V4L2_PIX_FMT_GREY, V4L2_PIX_FMT_MJPEG};
    for (const std::uint32_t f : formats)
        if (f == fourcc)
            return true;
    return false;
}

bool isDepthFormat(std::uint32_t fourcc)
{
    return fourcc == V4L2_PIX_FMT_Z16;
}

std::size_t strideOf(const PixelLayout& layout)
{
    return strideFor(layout.width, layout.bytesPerLine, bytesPerPixel(layout.fourcc));
}

std::size_t minimumFrameBytes(const PixelLayout& layout)
{
    if (layout.width <= 0 || layout.height <= 0)
        return 0;
    const std::size_t rows = static_cast<std::size_t>(layout.height);
    const std::size_t stride = strideOf(layout);
    return layout.fourcc == V4L2_PIX_FMT_NV12 ? stride * (rows + rows / 2) : stride * rows;
}

cv::Mat convertYuyv(std::span<const std::uint8_t> data, int width, int height,
                    std::size_t bytesPerLine)
{
    if (width % 2 != 0)
        return {};
    const cv::Mat yuyv = view(data, height, width, CV_8UC2, strideFor(width, bytesPerLine, 2));
    if (yuyv.empty())
        return {};
    cv::Mat bgr;
    cv::cvtColor(yuyv, bgr, cv::COLOR_YUV2BGR_YUYV);
    return bgr;
}

cv::Mat convertNv12(std::span<const std::uint8_t> data, int width, int height,
                    std::size_t bytesPerLine)
{
    if (width % 2 != 0 || height % 2 != 0)
        return {};
    // OpenCV reads NV12 as one 8-bit image of height * 3/2 rows: the Y rows, then the UV rows.
    const cv::Mat nv12 =
        view(data, height + height / 2, width, CV_8UC1, strideFor(width, bytesPerLine, 1));
    if (nv12.empty())
        return {};
    cv::Mat bgr;
    cv::cvtColor(nv12, bgr, cv::COLOR_YUV2BGR_NV12);
    return bgr;
}

cv::Mat convertRgb24(std::span<const std::uint8_t> data, int width, int height,
                     std::size_t bytesPerLine, bool bgrOrder)
{
    const cv::Mat packed = view(data, height, width, CV_8UC3, strideFor(width, bytesPerLine, 3));
    if (packed.empty())
        return {};
    cv::Mat bgr;
    if (bgrOrder)
        packed.copyTo(bgr);
    else
        cv::cvtColor(packed, bgr, cv::COLOR_RGB2BGR);
    return bgr;
}

cv::Mat convertGrey(std::span<const std::uint8_t> data, int width, int height,
                    std::size_t bytesPerLine)
{
    const cv::Mat grey = view(data, height, width, CV_8UC1, strideFor(width, bytesPerLine, 1));
    if (grey.empty())
        return {};
    cv::Mat bgr;
    cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
    return bgr;
}

cv::Mat convertMjpeg(std::span<const std::uint8_t> data)
{
    if (data.size() < 4 || data[0] != 0xFF || data[1] != 0xD8) // SOI marker
        return {};
    const cv::Mat bytes(1, static_cast<int>(data.size()), CV_8UC1,
                        const_cast<std::uint8_t*>(data.data()));
    try {
        cv::Mat bgr = cv::imdecode(bytes, cv::IMREAD_COLOR);
        return bgr.type() == CV_8UC3 ? bgr : cv::Mat();
    } catch (const cv::Exception&) {
        return {};
    }
}

cv::Mat convertZ16(std::span<const std::uint8_t> data, int width, int height, std::size_t bytesPerLine)
{
    static_assert(std::endian::native == std::endian::little, "Z16 is little-endian");
    return view(data, height, width, CV_16UC1, strideFor(width, bytesPerLine, 2)).clone();
}

cv::Mat convert(std::span<const std::uint8_t> data, const PixelLayout& layout)
{
    const int w = layout.width, h = layout.height;
    const std::size_t stride = layout.bytesPerLine;
    switch (layout.fourcc) {
    case V4L2_PIX_FMT_YUYV:
        return convertYuyv(data, w, h, stride);
    case V4L2_PIX_FMT_NV12:
        return convertNv12(data, w, h, stride);
    case V4L2_PIX_FMT_RGB24:
        return convertRgb24(data, w, h, stride, false);
    case V4L2_PIX_FMT_BGR24:
        return convertRgb24(data, w, h, stride, true);
    case V4L2_PIX_FMT_GREY:
        return convertGrey(data, w, h, stride);
    case V4L2_PIX_FMT_MJPEG:
        return convertMjpeg(data);
    case V4L2_PIX_FMT_Z16:
        return convertZ16(data, w, h, stride);
    default:
        return {};
    }
}

YuvEncoding yuvEncoding(std::uint32_t colorspace, std::uint32_t ycbcrEnc, std::uint32_t quantization)
{
    if (ycbcrEnc == V4L2_YCBCR_ENC_DEFAULT)
        ycbcrEnc = V4L2_MAP_YCBCR_ENC_DEFAULT(colorspace);
    if (quantization == V4L2_QUANTIZATION_DEFAULT)
        quantization = V4L2_MAP_QUANTIZATION_DEFAULT(false, colorspace, ycbcrEnc);
    YuvEncoding encoding;
    encoding.range = quantization == V4L2_QUANTIZATION_FULL_RANGE ? YuvImage::Range::Full : YuvImage::Range::Limited;
    switch (ycbcrEnc) {
    case V4L2_YCBCR_ENC_601:
    case V4L2_YCBCR_ENC_XV601: break;
    case V4L2_YCBCR_ENC_709:
    case V4L2_YCBCR_ENC_XV709: encoding.matrix = YuvImage::Matrix::Bt709; break;
    default: encoding.supported = false; break;
    }
    return encoding;
}

std::optional<YuvImage> capturedYuv(std::span<const std::uint8_t> data, const PixelLayout& layout)
{
    const int w = layout.width, h = layout.height;
    YuvImage image;
    image.layout = YuvImage::Layout::Yuyv;
    image.matrix = layout.matrix;
    image.range = layout.range;
    switch (layout.fourcc) {
    case V4L2_PIX_FMT_YUYV:
        if (w % 2 != 0)
            return std::nullopt;
        image.y = view(data, h, w, CV_8UC2, strideFor(w, layout.bytesPerLine, 2)).clone();
        break;
    case V4L2_PIX_FMT_NV12: {
        if (w % 2 != 0 || h % 2 != 0)
            return std::nullopt;
        // Y rows, then the interleaved CbCr rows at the same stride (single-plane NV12).
        const cv::Mat planes = view(data, h + h / 2, w, CV_8UC1, strideFor(w, layout.bytesPerLine, 1));
        if (planes.empty())
            return std::nullopt;
        image.layout = YuvImage::Layout::Nv12;
        image.y = planes.rowRange(0, h).clone();
        image.u = planes.rowRange(h, h + h / 2).reshape(2).clone();
        break;
    }
    default: return std::nullopt;
    }
    if (image.y.empty())
        return std::nullopt;
    return image;
}

} // namespace defocus::v4l2
