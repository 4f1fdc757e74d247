// SPDX-License-Identifier: LGPL-2.1-or-later
// The sRGB transfer functions on the CPU (the GPU uses sRGB textures and framebuffers).
#pragma once

#include <opencv2/core.hpp>

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

} // namespace defocus
