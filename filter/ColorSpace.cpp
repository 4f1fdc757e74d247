// SPDX-License-Identifier: LGPL-2.1-or-later
// sRGB decode/encode, with a 256-entry table for 8-bit decode; 8-bit Y'CbCr (4:2:0, YUYV) to BGR.
#include "filter/ColorSpace.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>

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

YuvCoefficients yuvCoefficients(YuvImage::Matrix matrix, YuvImage::Range range)
{
    const double kr = matrix == YuvImage::Matrix::Bt601 ? 0.299 : 0.2126;
    const double kb = matrix == YuvImage::Matrix::Bt601 ? 0.114 : 0.0722;
    const double kg = 1.0 - kr - kb;
    const bool limited = range == YuvImage::Range::Limited;
    const double chroma = limited ? 255.0 / 224.0 : 1.0; // Cb and Cr span 224 codes, or 255
    const auto fixed = [](double x) { return static_cast<int>(std::lround(256.0 * x)); };
    YuvCoefficients c;
    c.yOffset = limited ? 16 : 0;
    c.yScale = fixed(limited ? 255.0 / 219.0 : 1.0);
    c.crToR = fixed(2.0 * (1.0 - kr) * chroma);
    c.cbToG = fixed(2.0 * kb * (1.0 - kb) / kg * chroma);
    c.crToG = fixed(2.0 * kr * (1.0 - kr) / kg * chroma);
    c.cbToB = fixed(2.0 * (1.0 - kb) * chroma);
    return c;
}

int yuvPlaneCount(YuvImage::Layout layout)
{
    return layout == YuvImage::Layout::I420 ? 3 : layout == YuvImage::Layout::Nv12 ? 2 : 1;
}

std::string yuvProblem(const YuvImage& image)
{
    if (image.y.empty())
        return "Y'CbCr image: the luma plane (y) is empty";
    if (image.layout == YuvImage::Layout::Yuyv) {
        if (image.y.type() != CV_8UC2)
            return fmt::format("Y'CbCr image: a YUYV image's y is {}; expected its packed pairs, 8-bit two-channel "
                               "(CV_8UC2)",
                               cv::typeToString(image.y.type()));
        if (image.y.cols % 2 != 0)
            return fmt::format("Y'CbCr image: a YUYV image is {} pixels wide; it has pairs of pixels, an even width",
                               image.y.cols);
        if (!image.u.empty() || !image.v.empty())
            return "Y'CbCr image: u and v are for I420 and NV12; a YUYV image has Cb and Cr in y";
        return {};
    }
    if (image.y.type() != CV_8UC1)
        return fmt::format("Y'CbCr image: the luma plane (y) is {}; expected 8-bit (CV_8UC1)",
                           cv::typeToString(image.y.type()));
    const cv::Size half((image.y.cols + 1) / 2, (image.y.rows + 1) / 2);
    const bool nv12 = image.layout == YuvImage::Layout::Nv12;
    const auto plane = [&](const cv::Mat& m, const char* name, int type) -> std::string {
        if (m.type() == type && m.size() == half)
            return {};
        return fmt::format("Y'CbCr image: {} is {} {}x{}; expected {} {}x{} for a {}x{} {} image", name,
                           m.empty() ? std::string("empty") : cv::typeToString(m.type()), m.cols, m.rows,
                           cv::typeToString(type), half.width, half.height, image.y.cols, image.y.rows,
                           nv12 ? "NV12" : "I420");
    };
    if (nv12) {
        if (!image.v.empty())
            return "Y'CbCr image: v is for I420's Cr plane; an NV12 image has Cb and Cr in u";
        return plane(image.u, "the chroma plane (u)", CV_8UC2);
    }
    if (std::string problem = plane(image.u, "the Cb plane (u)", CV_8UC1); !problem.empty())
        return problem;
    return plane(image.v, "the Cr plane (v)", CV_8UC1);
}

cv::Mat convertYuv(const YuvImage& image)
{
    const YuvCoefficients c = yuvCoefficients(image.matrix, image.range);
    const bool nv12 = image.layout == YuvImage::Layout::Nv12;
    const bool yuyv = image.layout == YuvImage::Layout::Yuyv;
    cv::Mat bgr(image.y.size(), CV_8UC3);
    const auto clamp8 = [](int v) { return static_cast<std::uint8_t>(std::clamp(v >> 8, 0, 255)); };
    cv::parallel_for_(cv::Range(0, bgr.rows), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            // Each pixel's Y' at luma[x * lumaStep], its pair's (or block's) Cb and Cr at
            // cb[(x / 2) * step] and cr[(x / 2) * step].
            const std::uint8_t* luma = image.y.ptr<std::uint8_t>(y);
            const std::uint8_t* cb = yuyv ? luma + 1 : image.u.ptr<std::uint8_t>(y / 2);
            const std::uint8_t* cr = yuyv ? luma + 3 : nv12 ? cb + 1 : image.v.ptr<std::uint8_t>(y / 2);
            const int lumaStep = yuyv ? 2 : 1, step = yuyv ? 4 : nv12 ? 2 : 1;
            auto* out = bgr.ptr<std::uint8_t>(y);
            for (int x = 0; x < bgr.cols; ++x) {
                const int l = c.yScale * (luma[x * lumaStep] - c.yOffset) + 128;
                const int u = cb[(x / 2) * step] - 128, v = cr[(x / 2) * step] - 128;
                out[3 * x + 0] = clamp8(l + c.cbToB * u);
                out[3 * x + 1] = clamp8(l - c.cbToG * u - c.crToG * v);
                out[3 * x + 2] = clamp8(l + c.crToR * v);
            }
        }
    });
    return bgr;
}

} // namespace defocus
