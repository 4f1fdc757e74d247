// SPDX-License-Identifier: LGPL-2.1-or-later
// Scene analysis: the measurement of a frame, the CoC ranges, the foreground's reach and the plan.
#include "filter/SceneAnalysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "filter/ColorSpace.hpp"
#include "filter/FrameGraph.hpp"

namespace defocus {

namespace {

/// Rec. 709 luminance of linear BGR.
float luminanceBgr(float b, float g, float r)
{
    return 0.0722f * b + 0.7152f * g + 0.2126f * r;
}

/// Per tile, the sums over the 3x3 tiles around it that lie in the frame: pixels, highlight
/// pixels, luminance (SceneAnalysis::tileNeighbourhood).
cv::Mat neighbourhoods(const SceneMeasurement& m, cv::Size frame)
{
    constexpr int T = SceneAnalysis::kTileSize;
    cv::Mat out(m.tiles, CV_32FC4);
    for (int ty = 0; ty < m.tiles.height; ++ty)
        for (int tx = 0; tx < m.tiles.width; ++tx) {
            cv::Vec4f sum(0.0f, 0.0f, 0.0f, 0.0f);
            for (int y = std::max(ty - 1, 0); y <= std::min(ty + 1, m.tiles.height - 1); ++y)
                for (int x = std::max(tx - 1, 0); x <= std::min(tx + 1, m.tiles.width - 1); ++x) {
                    const int w = std::min(T, frame.width - x * T), h = std::min(T, frame.height - y * T);
                    sum[0] += static_cast<float>(w * h);
                    sum[1] += static_cast<float>(m.tileHighlights.at<int>(y, x));
                    sum[2] += m.tileLuminance.at<float>(y, x);
                }
            out.at<cv::Vec4f>(ty, tx) = sum;
        }
    return out;
}

} // namespace

float SceneAnalysis::maxAbsCoc() const
{
    return std::max(std::abs(minCoc), std::abs(maxCoc));
}

bool SceneAnalysis::tileNeedsBlur(int x, int y, float sharpBelowPx) const
{
    return std::max(std::abs(tileMinCoc.at<float>(y, x)), std::abs(tileMaxCoc.at<float>(y, x))) >= sharpBelowPx;
}

SceneMeasurement measureScene(const cv::Mat& filledDepth, const cv::Mat& color, const CocCoefficients& k)
{
    CV_Assert(filledDepth.type() == CV_32FC1 && filledDepth.size() == color.size() &&
              (color.type() == CV_8UC3 || color.type() == CV_8UC4 || color.type() == CV_32FC3));
    const int channels = color.channels(); // BGR, or BGRx whose fourth byte is not looked at
    SceneMeasurement m;
    constexpr int T = SceneAnalysis::kTileSize;
    m.tiles = {(filledDepth.cols + T - 1) / T, (filledDepth.rows + T - 1) / T};
    m.frame = filledDepth.size();
    m.pixels = filledDepth.total();

    // Rows of tiles are independent: OpenCV's threads take them in bands, each band with its
    // own counts, the depth and the colour of a band in one visit. Each row's |CoC| goes to a
    // buffer first and the histogram's edges are counted over it, loops the compiler vectorises
    // (with a bin index per pixel, one increment at a time, and a tile's sums kept in memory, the
    // TUM clip's analysis at 1920x1080 took 8.5 instead of 6.0 ms: docs/benchmarks.md).
    // Highlights: 8-bit, any channel clipped (>= 250); float, luminance above 1. With the
    // luminance summed (linear: 8-bit decoded from sRGB), per tile.
    constexpr std::size_t kEdges = SceneAnalysis::kHistogramEdges.size();
    std::array<float, 256> decode{};
    for (std::size_t i = 0; i < decode.size(); ++i)
        decode[i] = srgbToLinear(static_cast<float>(i) / 255.0f);
    m.tileMinDepth.create(m.tiles, CV_32F);
    m.tileMaxDepth.create(m.tiles, CV_32F);
    m.tileHighlights = cv::Mat::zeros(m.tiles, CV_32S);
    m.tileLuminance = cv::Mat::zeros(m.tiles, CV_32F);
    // Per band: the pixels whose |CoC| reaches each edge.
    std::vector<std::array<std::size_t, kEdges>> bandReach(static_cast<std::size_t>(m.tiles.height));
    cv::parallel_for_(cv::Range(0, m.tiles.height), [&](const cv::Range& range) {
        std::vector<float> coc(static_cast<std::size_t>(filledDepth.cols));
        for (int ty = range.start; ty < range.end; ++ty) {
            float* lo = m.tileMinDepth.ptr<float>(ty);
            float* hi = m.tileMaxDepth.ptr<float>(ty);
            std::fill(lo, lo + m.tiles.width, std::numeric_limits<float>::max());
            std::fill(hi, hi + m.tiles.width, std::numeric_limits<float>::lowest());
            std::array<std::size_t, kEdges>& reach = bandReach[static_cast<std::size_t>(ty)];
            reach.fill(0);
            int* counts = m.tileHighlights.ptr<int>(ty);
            float* sums = m.tileLuminance.ptr<float>(ty);
            for (int y = ty * T; y < std::min((ty + 1) * T, filledDepth.rows); ++y) {
                const float* z = filledDepth.ptr<float>(y);
                for (int tx = 0; tx < m.tiles.width; ++tx) {
                    float tileLo = lo[tx], tileHi = hi[tx];
                    for (int x = tx * T; x < std::min((tx + 1) * T, filledDepth.cols); ++x) {
                        tileLo = std::min(tileLo, z[x]);
                        tileHi = std::max(tileHi, z[x]);
                    }
                    lo[tx] = tileLo;
                    hi[tx] = tileHi;
                }
                for (int x = 0; x < filledDepth.cols; ++x)
                    coc[static_cast<std::size_t>(x)] = std::abs(cocPixels(k, z[x]));
                for (std::size_t i = 0; i < kEdges; ++i) {
                    const float edge = SceneAnalysis::kHistogramEdges[i];
                    int reached = 0;
                    for (const float c : coc)
                        reached += c >= edge ? 1 : 0;
                    reach[i] += static_cast<std::size_t>(reached);
                }
                // A tile's count and sum in registers across its pixels of the row (in memory,
                // each pixel waited for the previous one's store).
                for (int tx = 0; tx < m.tiles.width; ++tx) {
                    const int x0 = tx * T, x1 = std::min(x0 + T, color.cols);
                    int count = counts[tx];
                    float sum = sums[tx];
                    if (color.depth() == CV_8U) {
                        const std::uint8_t* p = color.ptr<std::uint8_t>(y) + channels * x0;
                        for (int x = x0; x < x1; ++x, p += channels) {
                            count += std::max(p[0], std::max(p[1], p[2])) >= 250 ? 1 : 0;
                            sum += luminanceBgr(decode[p[0]], decode[p[1]], decode[p[2]]);
                        }
                    } else {
                        const float* p = color.ptr<float>(y) + 3 * x0;
                        for (int x = x0; x < x1; ++x, p += 3) {
                            const float brightness = luminanceBgr(p[0], p[1], p[2]);
                            count += brightness > 1.0f ? 1 : 0;
                            sum += brightness;
                        }
                    }
                    counts[tx] = count;
                    sums[tx] = sum;
                }
            }
        }
    });
    // Bin b holds the pixels that reach edge b - 1 but not edge b.
    std::array<std::size_t, kEdges> reach{};
    for (const auto& band : bandReach)
        for (std::size_t i = 0; i < kEdges; ++i)
            reach[i] += band[i];
    std::size_t previous = m.pixels;
    for (std::size_t i = 0; i < kEdges; ++i) {
        m.histogram[i] = static_cast<int>(previous - reach[i]);
        previous = reach[i];
    }
    m.histogram[kEdges] = static_cast<int>(previous);
    m.highlightPixels = static_cast<std::size_t>(cv::sum(m.tileHighlights)[0]);
    return m;
}

SceneAnalysis finishAnalysis(const SceneMeasurement& m, const CocCoefficients& k, double invalidDepthFraction)
{
    CV_Assert(m.tileMinDepth.size() == m.tiles && m.tileMaxDepth.size() == m.tiles && m.pixels > 0);
    constexpr int T = SceneAnalysis::kTileSize;
    SceneAnalysis a;
    a.tiles = m.tiles;
    a.invalidDepthFraction = invalidDepthFraction;
    a.histogram = m.histogram;
    a.tileMinCoc.create(a.tiles, CV_32F);
    a.tileMaxCoc.create(a.tiles, CV_32F);
    a.minCoc = std::numeric_limits<float>::max();
    a.maxCoc = std::numeric_limits<float>::lowest();
    for (int ty = 0; ty < a.tiles.height; ++ty)
        for (int tx = 0; tx < a.tiles.width; ++tx) {
            const float lo = cocPixels(k, m.tileMinDepth.at<float>(ty, tx));
            const float hi = cocPixels(k, m.tileMaxDepth.at<float>(ty, tx));
            a.tileMinCoc.at<float>(ty, tx) = std::min(lo, hi);
            a.tileMaxCoc.at<float>(ty, tx) = std::max(lo, hi);
            a.minCoc = std::min(a.minCoc, std::min(lo, hi));
            a.maxCoc = std::max(a.maxCoc, std::max(lo, hi));
        }
    a.foreground = a.minCoc <= -0.5f;

    // Foreground reach: a near pixel of diameter d blurs pixels up to d/2 away. One extra tile
    // covers the linear filtering of this map between tile centres.
    a.tileNearDiameter = cv::max(-a.tileMinCoc, 0.0f);
    a.tileNearDiameter.setTo(0.0f, a.tileNearDiameter < 0.5f);
    if (a.foreground) {
        const int reach = static_cast<int>(std::ceil(-a.minCoc / 2.0f / static_cast<float>(T))) + 1;
        cv::dilate(a.tileNearDiameter, a.tileNearDiameter,
                   cv::getStructuringElement(cv::MORPH_RECT, {2 * reach + 1, 2 * reach + 1}));
    }
    a.highlightPixels = m.highlightPixels;
    if (m.highlightPixels > 0) {
        CV_Assert(m.tileHighlights.size() == m.tiles && m.tileHighlights.type() == CV_32SC1 &&
                  m.tileLuminance.size() == m.tiles && m.tileLuminance.type() == CV_32FC1);
        for (int ty = 0; ty < a.tiles.height; ++ty)
            for (int tx = 0; tx < a.tiles.width; ++tx)
                if (m.tileHighlights.at<int>(ty, tx) > 0)
                    a.highlightTiles.emplace_back(tx, ty);
        a.tileNeighbourhood = neighbourhoods(m, m.frame);
    }
    a.highlightFraction = static_cast<double>(m.highlightPixels) / static_cast<double>(m.pixels);
    return a;
}

SceneAnalysis analyseScene(const cv::Mat& filledDepth, const cv::Mat& color, const CocCoefficients& k,
                           double invalidDepthFraction)
{
    return finishAnalysis(measureScene(filledDepth, color, k), k, invalidDepthFraction);
}

int halfOrQuarterShift(const SceneAnalysis& analysis)
{
    // Histogram bins: |CoC| below each edge; the last bin takes the rest.
    const auto& edges = SceneAnalysis::kHistogramEdges;
    std::size_t blurred = 0, large = 0;
    for (std::size_t i = 0; i < analysis.histogram.size(); ++i) {
        const float lower = i == 0 ? 0.0f : edges[i - 1];
        const auto count = static_cast<std::size_t>(std::max(analysis.histogram[i], 0));
        if (lower >= 1.0f)
            blurred += count;
        if (lower >= kQuarterCocPx)
            large += count;
    }
    return blurred > 0 && static_cast<double>(large) > kQuarterShare * static_cast<double>(blurred) ? 2 : 1;
}

FramePlan makePlan(const SceneAnalysis& analysis, bool nearField, HexagonKernel kernel, Resolution resolution,
                   int taps, bool quarterOnLargeBlur)
{
    FramePlan plan;
    plan.blurShift = resolution == Resolution::Full ? 0 : quarterOnLargeBlur ? halfOrQuarterShift(analysis) : 1;
    plan.allInFocus = analysis.allInFocus();
    plan.holeFill = analysis.invalidDepthFraction > 0.0;
    plan.highlights = analysis.hasHighlights();
    plan.foreground = analysis.foreground;
    if (plan.allInFocus)
        return plan;
    plan.nearField = nearField && analysis.foreground;
    plan.kernel = kernel;
    // The blur passes leave a pixel alone below this |CoC|: McIntosh's at 0.5 px, the rhombi's at
    // 1 px (a line shorter than half a pixel is the centre alone), so their tiles skip more.
    const float sharpBelow = kernel == HexagonKernel::RhombiSum ? 1.0f : 0.5f;
    for (int y = 0; y < analysis.tiles.height; ++y)
        for (int x = 0; x < analysis.tiles.width; ++x) {
            const bool near = plan.nearField && analysis.tileNearDiameter.at<float>(y, x) >= sharpBelow;
            if (near)
                plan.nearTiles.emplace_back(x, y);
            // The rhombus blur handles the foreground itself: tiles it reaches are blurred too.
            const bool blur = analysis.tileNeedsBlur(x, y, sharpBelow) || (near && kernel == HexagonKernel::RhombiSum);
            (blur ? plan.blurTiles : plan.copyTiles).emplace_back(x, y);
            if (plan.blurShift != 0) {
                // upscale.frag's detail weight is 0 from |CoC| = 2 px (4 at quarter size): a
                // tile whose whole range lies beyond has nothing to put back.
                const float detailBelow = upscaleDetailBelowPx(plan.blurShift);
                const bool detail = analysis.tileMinCoc.at<float>(y, x) < detailBelow &&
                                    analysis.tileMaxCoc.at<float>(y, x) > -detailBelow;
                if (detail)
                    plan.detailTiles.emplace_back(x, y);
            }
        }
    plan.resolution = resolution;

    // Unrolled loops where at least half the blurred tiles have a line 3/4 as long as `taps` or
    // longer: the tile's largest blur or the foreground reaching it, halved (a line's length),
    // in the blur's pixels. On llvmpipe, 640x480: the TUM clip at half size (lines mostly 1-4 px) 13.5-15.1 ms
    // per frame with plain loops of 6 taps against 16.5 unrolled; the Blender scene at full size
    // (most lines 7 px) 38.6 ms unrolled against 43.8.
    if (kernel == HexagonKernel::RhombiSum && taps > 0 && !plan.blurTiles.empty()) {
        const float scale = 0.5f / static_cast<float>(1 << plan.blurShift);
        std::size_t saturated = 0;
        for (const cv::Point& tile : plan.blurTiles) {
            const float blur = std::max(std::abs(analysis.tileMinCoc.at<float>(tile)),
                                        std::abs(analysis.tileMaxCoc.at<float>(tile)));
            const float near = plan.nearField ? analysis.tileNearDiameter.at<float>(tile) : 0.0f;
            saturated += std::max(blur, near) * scale >= 0.75f * static_cast<float>(taps) ? 1 : 0;
        }
        plan.unrolledTaps = 2 * saturated >= plan.blurTiles.size();
    }
    return plan;
}

std::string FramePlan::explain(const SceneAnalysis& analysis) const
{
    const int total = analysis.tiles.area();
    std::string text = allInFocus ? fmt::format("all in focus (max |CoC| {:.2f} px): input passed through, no pass ran",
                                                analysis.maxAbsCoc())
                                  : fmt::format("{}; blur on {}/{} tiles (copy {}); CoC {:+.1f}..{:+.1f} px",
                                                describe(compositeFrame({kernel, blurShift != 0, nearField,
                                                                         highlightSprites})),
                                                blurTiles.size(), total, copyTiles.size(),
                                                analysis.minCoc / gatherScale, analysis.maxCoc / gatherScale);
    if (allInFocus)
        return text + " (hole filling and analysis skipped)";
    if (blurShift != 0)
        text += fmt::format("; {} size, upscale puts detail back on {}/{} tiles", blurShift == 2 ? "quarter" : "half",
                            detailTiles.size(), total);
    text += holeFill ? fmt::format("; hole fill on ({:.1f} % invalid)", 100.0 * analysis.invalidDepthFraction)
                     : "; hole fill off (no holes)";
    if (kernel == HexagonKernel::RhombiSum)
        text += unrolledTaps ? "; tap loops unrolled" : "; tap loops plain";
    text += nearField ? fmt::format("; near field on {} tiles", nearTiles.size())
                      : foreground ? "; foreground blur, near field off" : "; no foreground blur, near field off";
    text += highlights ? fmt::format("; highlights {:.2f} %{}", 100.0 * analysis.highlightFraction,
                                     highlightSprites ? " (bokeh sprites)" : "")
                       : "; no highlights";
    if (highlightGain > 1.0)
        text += fmt::format(" (recovered x{:g})", highlightGain);
    return text;
}

} // namespace defocus
