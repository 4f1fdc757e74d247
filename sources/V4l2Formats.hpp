// SPDX-License-Identifier: LGPL-2.1-or-later
// Conversions of V4L2 pixel formats into what a Frame holds: colour formats to BGR CV_8UC3 (or
// YUYV and NV12 kept as Y'CbCr planes), Z16 depth as 16-bit units. Pure functions on bytes, so tests check them without a camera.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <opencv2/core.hpp>

#include "defocus/Frame.hpp"

namespace defocus::v4l2 {

/// "YUYV" for V4L2_PIX_FMT_YUYV, "Z16 " for V4L2_PIX_FMT_Z16; unprintable bytes become '?'.
std::string fourccName(std::uint32_t fourcc);
/// The code of a 1-4 character name ("MJPG", "Z16"; shorter names are padded with spaces, as
/// V4L2 spells them). Names longer than 4 characters give 0.
std::uint32_t fourccFromName(std::string_view name);

/// The formats V4l2Source decodes: YUYV, NV12, RGB3, BGR3, GREY, MJPG (colour) and Z16 (depth).
bool isColorFormat(std::uint32_t fourcc);
bool isDepthFormat(std::uint32_t fourcc);

/// One captured image as the driver lays it out (from VIDIOC_S_FMT).
struct PixelLayout {
    std::uint32_t fourcc = 0;     ///< V4L2_PIX_FMT_*
    int width = 0;                ///< pixels, > 0
    int height = 0;               ///< pixels, > 0
    std::size_t bytesPerLine = 0; ///< stride of the first plane in bytes; 0 = tightly packed
    /// YUYV and NV12: the encoding the driver states (yuvEncoding()), for capturedYuv().
    YuvImage::Matrix matrix = YuvImage::Matrix::Bt601;
    YuvImage::Range range = YuvImage::Range::Limited;
};

/// How a driver's Y'CbCr is encoded, from VIDIOC_S_FMT's answer.
struct YuvEncoding {
    YuvImage::Matrix matrix = YuvImage::Matrix::Bt601;
    YuvImage::Range range = YuvImage::Range::Limited;
    /// False where the matrix is one YuvImage has not (BT.2020, SMPTE 240M): BT.601 stands in.
    bool supported = true;
};
/// The encoding of `colorspace`, `ycbcrEnc` and `quantization` (v4l2_pix_format's fields; pass
/// the DEFAULT values where the driver has not set priv to V4L2_PIX_FMT_PRIV_MAGIC), their
/// defaults resolved as V4L2 resolves them (V4L2_MAP_YCBCR_ENC_DEFAULT,
/// V4L2_MAP_QUANTIZATION_DEFAULT): BT.709 for REC709 and DCI-P3, full range for JPEG, and
/// otherwise BT.601 limited range, what UVC webcams and vivid at SD sizes send.
YuvEncoding yuvEncoding(std::uint32_t colorspace, std::uint32_t ycbcrEnc, std::uint32_t quantization);

/// The stride `layout` implies: its bytesPerLine, or the packed stride when that is 0. 0 for
/// MJPEG (no rows).
std::size_t strideOf(const PixelLayout& layout);
/// Bytes a frame of `layout` needs at least (stride x rows, plus the chroma plane of NV12); 0 for
/// MJPEG, whose frames vary in size.
std::size_t minimumFrameBytes(const PixelLayout& layout);

// Each conversion reads `data` as one image of the given layout and returns a new image that
// owns its pixels (the capture buffer can be handed back to the driver at once). They return an
// empty Mat when `data` is too short for the layout or the layout is odd (YUYV and NV12 need an
// even width; NV12 an even height).

/// YUYV 4:2:2 (Y0 U Y1 V), BT.601 limited range (16-235 luma), the encoding of UVC webcams and of
/// vivid at SD sizes: Y=16 is black, Y=235 white.
cv::Mat convertYuyv(std::span<const std::uint8_t> data, int width, int height,
                    std::size_t bytesPerLine);
/// NV12: a full-resolution Y plane, then a half-resolution interleaved U,V plane with the same
/// stride, directly after the last Y row (V4L2's single-plane NV12). BT.601 limited range.
cv::Mat convertNv12(std::span<const std::uint8_t> data, int width, int height,
                    std::size_t bytesPerLine);
/// RGB3 (bytes R,G,B) when `bgrOrder` is false, BGR3 (bytes B,G,R) when true.
cv::Mat convertRgb24(std::span<const std::uint8_t> data, int width, int height,
                     std::size_t bytesPerLine, bool bgrOrder);
/// GREY: 8-bit luma, full range, copied into all three channels.
cv::Mat convertGrey(std::span<const std::uint8_t> data, int width, int height,
                    std::size_t bytesPerLine);
/// MJPG: one JPEG image decoded with cv::imdecode (trailing bytes after the end-of-image marker
/// are ignored, so a buffer whose bytesused is the whole buffer still decodes).
cv::Mat convertMjpeg(std::span<const std::uint8_t> data);
/// Z16: little-endian 16-bit depth, copied as it is into CV_16UC1 (the camera's units; 0 = no
/// measurement).
cv::Mat convertZ16(std::span<const std::uint8_t> data, int width, int height, std::size_t bytesPerLine);

/// The conversion for `layout.fourcc`: colour formats give BGR CV_8UC3, Z16 its 16-bit units.
/// Empty for other formats, short data, or a JPEG that does not decode.
cv::Mat convert(std::span<const std::uint8_t> data, const PixelLayout& layout);

/// YUYV and NV12 as they were captured, for the filter to upload as they are: the planes copied
/// out of `data` (rows packed, the driver's padding dropped) into a YuvImage that owns them,
/// with the layout's matrix and range (convertYuyv() and convertNv12() read BT.601 limited
/// range whatever the driver says). nullopt for other formats, short data or an odd layout (the
/// same as those conversions' empty results).
std::optional<YuvImage> capturedYuv(std::span<const std::uint8_t> data, const PixelLayout& layout);

} // namespace defocus::v4l2
