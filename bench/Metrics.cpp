// SPDX-License-Identifier: LGPL-2.1-or-later
// PSNR, SSIM and the region split of the error (see Metrics.hpp for the definitions).
#include "bench/Metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <opencv2/imgproc.hpp>

#include "filter/ColorSpace.hpp"

namespace defocus {

namespace {

/// Linear values clipped to [0, 1], NaN -> 0.
cv::Mat clipped(const cv::Mat& linear)
{
    CV_Assert(linear.type() == CV_32FC3);
    cv::Mat out(linear.size(), CV_32FC3);
    for (int y = 0; y < linear.rows; ++y) {
        const float* in = linear.ptr<float>(y);
        float* o = out.ptr<float>(y);
        for (int x = 0; x < linear.cols * 3; ++x)
            o[x] = std::isnan(in[x]) ? 0.0f : std::clamp(in[x], 0.0f, 1.0f);
    }
    return out;
}

cv::Mat srgbEncoded(const cv::Mat& linear)
{
    cv::Mat out = clipped(linear);
    for (int y = 0; y < out.rows; ++y) {
        float* o = out.ptr<float>(y);
        for (int x = 0; x < out.cols * 3; ++x)
            o[x] = linearToSrgb(o[x]);
    }
    return out;
}

/// Mean squared difference over the channels of the masked pixels; NaN when no pixel is masked.
double maskedMse(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask)
{
    CV_Assert(a.type() == CV_32FC3 && b.type() == CV_32FC3 && a.size() == b.size());
    CV_Assert(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == a.size()));
    double sum = 0.0;
    std::size_t count = 0;
    for (int y = 0; y < a.rows; ++y) {
        const float* pa = a.ptr<float>(y);
        const float* pb = b.ptr<float>(y);
        const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(y);
        for (int x = 0; x < a.cols; ++x) {
            if (m && !m[x])
                continue;
            for (int c = 0; c < 3; ++c) {
                const double d = static_cast<double>(pa[3 * x + c]) - static_cast<double>(pb[3 * x + c]);
                sum += d * d;
            }
            count += 3;
        }
    }
    return count == 0 ? std::nan("") : sum / static_cast<double>(count);
}

} // namespace

double psnrFromMse(double mse, double peak)
{
    if (std::isnan(mse))
        return mse;
    if (mse <= 0.0)
        return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(peak * peak / mse);
}

double psnrLinear(const cv::Mat& image, const cv::Mat& truth, const cv::Mat& mask)
{
    return psnrFromMse(maskedMse(clipped(image), clipped(truth), mask));
}

double psnrSrgb(const cv::Mat& image, const cv::Mat& truth, const cv::Mat& mask)
{
    return psnrFromMse(maskedMse(srgbEncoded(image), srgbEncoded(truth), mask));
}

cv::Mat srgbLuma(const cv::Mat& linear)
{
    const cv::Mat encoded = srgbEncoded(linear);
    cv::Mat luma(linear.size(), CV_32FC1);
    for (int y = 0; y < encoded.rows; ++y) {
        const float* e = encoded.ptr<float>(y);
        float* l = luma.ptr<float>(y);
        for (int x = 0; x < encoded.cols; ++x) // BGR order
            l[x] = 0.0722f * e[3 * x] + 0.7152f * e[3 * x + 1] + 0.2126f * e[3 * x + 2];
    }
    return luma;
}

double ssimLuma(const cv::Mat& image, const cv::Mat& truth)
{
    CV_Assert(image.size() == truth.size());
    constexpr int kWindow = 11;
    constexpr double kSigma = 1.5;
    constexpr double kC1 = 0.01 * 0.01; // (K1 L)^2 with L = 1
    constexpr double kC2 = 0.03 * 0.03; // (K2 L)^2
    const int border = kWindow / 2;
    if (image.rows <= 2 * border || image.cols <= 2 * border)
        return std::nan("");

    cv::Mat x, y;
    srgbLuma(image).convertTo(x, CV_64F);
    srgbLuma(truth).convertTo(y, CV_64F);
    const auto blur = [](const cv::Mat& m) {
        cv::Mat out;
        cv::GaussianBlur(m, out, cv::Size(kWindow, kWindow), kSigma, kSigma, cv::BORDER_REPLICATE);
        return out;
    };
    const cv::Mat muX = blur(x), muY = blur(y);
    const cv::Mat xx = blur(x.mul(x)), yy = blur(y.mul(y)), xy = blur(x.mul(y));

    double sum = 0.0;
    std::size_t count = 0;
    for (int r = border; r < x.rows - border; ++r) {
        for (int c = border; c < x.cols - border; ++c) {
            const double mx = muX.at<double>(r, c), my = muY.at<double>(r, c);
            const double vx = xx.at<double>(r, c) - mx * mx;
            const double vy = yy.at<double>(r, c) - my * my;
            const double cov = xy.at<double>(r, c) - mx * my;
            sum += ((2.0 * mx * my + kC1) * (2.0 * cov + kC2)) / ((mx * mx + my * my + kC1) * (vx + vy + kC2));
            ++count;
        }
    }
    return sum / static_cast<double>(count);
}

std::string_view regionName(Region region)
{
    switch (region) {
    case Region::InFocus: return "in-focus";
    case Region::OutOfFocus: return "out-of-focus";
    case Region::DepthEdge: return "depth-edge";
    }
    return "?";
}

cv::Mat cocMap(const cv::Mat& depthMetres, const CocCoefficients& k)
{
    CV_Assert(depthMetres.type() == CV_32FC1);
    cv::Mat coc(depthMetres.size(), CV_32FC1);
    for (int y = 0; y < coc.rows; ++y) {
        const float* z = depthMetres.ptr<float>(y);
        float* c = coc.ptr<float>(y);
        for (int x = 0; x < coc.cols; ++x)
            c[x] = cocPixels(k, z[x]);
    }
    return coc;
}

cv::Mat regionMap(const cv::Mat& cocPx, const RegionOptions& options)
{
    CV_Assert(cocPx.type() == CV_32FC1);
    const int rows = cocPx.rows, cols = cocPx.cols;

    // Edge pixels grouped by the integer radius of their band, so that each radius is one
    // dilation with a disc.
    std::map<int, cv::Mat> seeds;
    const auto mark = [&](int x, int y, float radius) {
        const int r = static_cast<int>(std::ceil(radius));
        cv::Mat& seed = seeds[r];
        if (seed.empty())
            seed = cv::Mat::zeros(rows, cols, CV_8UC1);
        seed.at<uchar>(y, x) = 255;
    };
    const auto pair = [&](int x0, int y0, int x1, int y1) {
        const float a = cocPx.at<float>(y0, x0), b = cocPx.at<float>(y1, x1);
        if (!(std::abs(a - b) > options.edgeJumpPx))
            return;
        const float radius = 0.5f * std::max(std::abs(a), std::abs(b)) + options.edgeMarginPx;
        mark(x0, y0, radius);
        mark(x1, y1, radius);
    };
    for (int y = 0; y < rows; ++y) {
        for (int x = 0; x < cols; ++x) {
            if (x + 1 < cols)
                pair(x, y, x + 1, y);
            if (y + 1 < rows)
                pair(x, y, x, y + 1);
        }
    }
    cv::Mat edge = cv::Mat::zeros(rows, cols, CV_8UC1);
    for (const auto& [radius, seed] : seeds) {
        cv::Mat grown;
        const cv::Mat disc = cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * radius + 1, 2 * radius + 1});
        cv::dilate(seed, grown, disc);
        edge |= grown;
    }

    cv::Mat labels(rows, cols, CV_8UC1);
    for (int y = 0; y < rows; ++y) {
        const float* c = cocPx.ptr<float>(y);
        const uchar* e = edge.ptr<uchar>(y);
        uchar* l = labels.ptr<uchar>(y);
        for (int x = 0; x < cols; ++x) {
            const Region region = e[x]                                ? Region::DepthEdge
                                  : std::abs(c[x]) < options.inFocusCocPx ? Region::InFocus
                                                                       : Region::OutOfFocus;
            l[x] = static_cast<uchar>(region);
        }
    }
    return labels;
}

ErrorReport measureError(const cv::Mat& image, const cv::Mat& truth, const cv::Mat& regions)
{
    CV_Assert(regions.type() == CV_8UC1 && regions.size() == image.size());
    ErrorReport report;
    const cv::Mat a = clipped(image), b = clipped(truth);
    report.psnrLinear = psnrFromMse(maskedMse(a, b, {}));
    report.psnrSrgb = psnrSrgb(image, truth);
    report.ssim = ssimLuma(image, truth);
    const double total = static_cast<double>(regions.total());
    for (const Region region : kRegions) {
        const cv::Mat mask = regions == static_cast<int>(region);
        const auto i = static_cast<std::size_t>(region);
        report.regionPsnr[i] = psnrFromMse(maskedMse(a, b, mask));
        report.regionShare[i] = static_cast<double>(cv::countNonZero(mask)) / total;
    }
    return report;
}

std::string_view zoneName(Zone zone)
{
    switch (zone) {
    case Zone::Lights: return "lights";
    case Zone::DepthEdge: return "depth-edges";
    case Zone::InFocus: return "in-focus";
    case Zone::Near: return "near";
    case Zone::Far: return "far";
    }
    return "?";
}

cv::Mat zoneMap(const cv::Mat& inputLinear, const cv::Mat& cocPx, const ZoneOptions& options)
{
    CV_Assert(inputLinear.type() == CV_32FC3 && cocPx.type() == CV_32FC1 && inputLinear.size() == cocPx.size());
    // Distance of every pixel to the nearest light: distanceTransform measures the distance to
    // the nearest zero, so lights are 0 and the rest 1.
    cv::Mat notLight(inputLinear.size(), CV_8UC1);
    for (int y = 0; y < inputLinear.rows; ++y) {
        const float* in = inputLinear.ptr<float>(y);
        uchar* o = notLight.ptr<uchar>(y);
        for (int x = 0; x < inputLinear.cols; ++x)
            o[x] = std::max({in[3 * x], in[3 * x + 1], in[3 * x + 2]}) > options.lightThreshold ? 0 : 1;
    }
    cv::Mat distance;
    cv::distanceTransform(notLight, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    const cv::Mat regions = regionMap(cocPx, options.regions);
    cv::Mat zones(inputLinear.size(), CV_8UC1);
    for (int y = 0; y < zones.rows; ++y) {
        const float* d = distance.ptr<float>(y);
        const float* c = cocPx.ptr<float>(y);
        const uchar* r = regions.ptr<uchar>(y);
        uchar* z = zones.ptr<uchar>(y);
        for (int x = 0; x < zones.cols; ++x) {
            Zone zone = c[x] < 0.0f ? Zone::Near : Zone::Far;
            if (d[x] <= options.lightRadiusPx)
                zone = Zone::Lights;
            else if (r[x] == static_cast<uchar>(Region::DepthEdge))
                zone = Zone::DepthEdge;
            else if (r[x] == static_cast<uchar>(Region::InFocus))
                zone = Zone::InFocus;
            z[x] = static_cast<uchar>(zone);
        }
    }
    return zones;
}

ZoneReport measureZones(const cv::Mat& image, const cv::Mat& truth, const cv::Mat& zones)
{
    CV_Assert(zones.type() == CV_8UC1 && zones.size() == image.size());
    ZoneReport report;
    const cv::Mat a = clipped(image), b = clipped(truth);
    const double total = static_cast<double>(zones.total());
    const double totalError = maskedMse(a, b, {}) * total;
    for (const Zone zone : kZones) {
        const cv::Mat mask = zones == static_cast<int>(zone);
        const auto i = static_cast<std::size_t>(zone);
        const double mse = maskedMse(a, b, mask);
        const double pixels = static_cast<double>(cv::countNonZero(mask));
        report.psnr[i] = psnrFromMse(mse);
        report.share[i] = pixels / total;
        report.errorShare[i] = pixels == 0.0 || totalError == 0.0 ? 0.0 : mse * pixels / totalError;
    }
    return report;
}

} // namespace defocus
