// SPDX-License-Identifier: LGPL-2.1-or-later
// sRGB decode/encode, with a 256-entry table for 8-bit decode.
#include "filter/ColorSpace.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace defocus {

float srgbToLinear(float v)
{
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float v)
{
    return v <= 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

cv::Mat decodeSrgb(const cv::Mat& srgb8)
{
    CV_Assert(srgb8.type() == CV_8UC3);
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i)
            t[static_cast<std::size_t>(i)] = srgbToLinear(static_cast<float>(i) / 255.0f);
        return t;
    }();
    cv::Mat out(srgb8.size(), CV_32FC3);
    for (int y = 0; y < srgb8.rows; ++y) {
        const auto* in = srgb8.ptr<uchar>(y);
        auto* o = out.ptr<float>(y);
        for (int x = 0; x < srgb8.cols * 3; ++x)
            o[x] = table[in[x]];
    }
    return out;
}

cv::Mat sanitizeLinear(const cv::Mat& linear, float largest)
{
    CV_Assert(linear.type() == CV_32FC3);
    cv::Mat out(linear.size(), CV_32FC3);
    for (int y = 0; y < linear.rows; ++y) {
        const auto* in = linear.ptr<float>(y);
        auto* o = out.ptr<float>(y);
        for (int x = 0; x < linear.cols * 3; ++x)
            o[x] = std::isnan(in[x]) ? 0.0f : std::clamp(in[x], 0.0f, largest);
    }
    return out;
}

cv::Mat encodeSrgb(const cv::Mat& linear)
{
    CV_Assert(linear.type() == CV_32FC3);
    cv::Mat out(linear.size(), CV_8UC3);
    for (int y = 0; y < linear.rows; ++y) {
        const auto* in = linear.ptr<float>(y);
        auto* o = out.ptr<uchar>(y);
        for (int x = 0; x < linear.cols * 3; ++x) {
            const float v = std::isnan(in[x]) ? 0.0f : std::clamp(in[x], 0.0f, 1.0f);
            o[x] = static_cast<uchar>(std::lround(linearToSrgb(v) * 255.0f));
        }
    }
    return out;
}

} // namespace defocus
