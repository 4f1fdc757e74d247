// SPDX-License-Identifier: LGPL-2.1-or-later
// The sRGB transfer functions on the CPU (the GPU uses sRGB textures and framebuffers), and 8-bit
// Y'CbCr (4:2:0 planes, YUYV's packed pairs) to BGR in the integer arithmetic the GPU's
// yuv_to_rgb.frag does too.
#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "defocus/Frame.hpp"

namespace defocus {

/// Exact IEC 61966-2-1 decode of one value in [0, 1].
float srgbToLinear(float v);
/// Exact encode of one linear value; values above 1 encode above 1.
float linearToSrgb(float v);
/// CV_8UC3 sRGB -> CV_32FC3 linear.
cv::Mat decodeSrgb(const cv::Mat& srgb8);
/// CV_32FC3 linear, made what the CoC pass makes of it: NaN -> 0, then clamped to [0, largest].
cv::Mat sanitizeLinear(const cv::Mat& linear, float largest);
/// CV_32FC3 linear -> CV_8UC3 sRGB, clipped to [0, 1] and rounded.
cv::Mat encodeSrgb(const cv::Mat& linear);

/// Y'CbCr -> R'G'B' in 8-bit fixed point (x256), as video players' integer paths do:
///   R = (yScale (Y - yOffset) + crToR (Cr - 128) + 128) >> 8
///   G = (yScale (Y - yOffset) - cbToG (Cb - 128) - crToG (Cr - 128) + 128) >> 8
///   B = (yScale (Y - yOffset) + cbToB (Cb - 128) + 128) >> 8,   each clamped to 0..255,
/// the factors rounded from the matrix' Kr and Kb and the range's scale (BT.601 limited: 298,
/// 409, 100, 208, 516).
struct YuvCoefficients {
    int yOffset = 16;
    int yScale = 298;
    int crToR = 409, cbToG = 100, crToG = 208, cbToB = 516;
};
YuvCoefficients yuvCoefficients(YuvImage::Matrix matrix, YuvImage::Range range);
/// The planes of `layout`, in YuvImage's order y, u, v: I420 3, NV12 2, YUYV 1.
int yuvPlaneCount(YuvImage::Layout layout);
/// What is wrong with `image`'s planes (types, sizes), in one line naming the plane; "" if nothing.
std::string yuvProblem(const YuvImage& image);
/// `image` as CV_8UC3 BGR: each pixel from its Y' and the Cb and Cr of its 2x2 block (4:2:0) or
/// of its pair (YUYV), nearest.
/// Its planes must have passed yuvProblem().
cv::Mat convertYuv(const YuvImage& image);

} // namespace defocus
