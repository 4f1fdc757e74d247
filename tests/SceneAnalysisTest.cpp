// SPDX-License-Identifier: LGPL-2.1-or-later
// The scene analysis (filter/SceneAnalysis): the tiles with highlights and the neighbourhoods the
// bokeh sprites judge lights in, and the plan's tap loops.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "filter/ColorSpace.hpp"
#include "filter/Lens.hpp"
#include "filter/SceneAnalysis.hpp"

namespace defocus {
namespace {

/// 75 x 41 float (tiles 5 x 3, the last column and row partial), dark grey with lights at
/// (3, 2), (17, 35) and (74, 40), and a pixel just below white (luminance 0.99) in tile (2, 0).
SceneAnalysis analyseLights()
{
    cv::Mat color(41, 75, CV_32FC3, cv::Scalar::all(0.2));
    color.at<cv::Vec3f>(2, 3) = cv::Vec3f(5.0f, 5.0f, 5.0f);
    color.at<cv::Vec3f>(35, 17) = cv::Vec3f(0.0f, 3.0f, 0.0f);
    color.at<cv::Vec3f>(40, 74) = cv::Vec3f(20.0f, 20.0f, 20.0f);
    color.at<cv::Vec3f>(5, 40) = cv::Vec3f(0.99f, 0.99f, 0.99f);
    const cv::Mat depth(color.size(), CV_32F, cv::Scalar(3.0));
    LensSettings lens;
    lens.focusM = 1.0;
    return analyseScene(depth, color, cocCoefficients(lens, color.cols), 0.0);
}

TEST(SceneAnalysisHighlights, HighlightTilesAreTheTilesWithAPixelAboveWhite)
{
    // Catches a tile of the list at the wrong place (column and row swapped, another tile's
    // count): the sprites would be looked for, and highlights treated by the CoC pass, where
    // there are none, and a light left in the gather. The pixel below white makes no tile.
    const std::vector<cv::Point> expected{{0, 0}, {1, 2}, {4, 2}};
    EXPECT_EQ(analyseLights().highlightTiles, expected);
}

TEST(SceneAnalysisHighlights, NeighbourhoodsSumTheTilesAroundInTheFrame)
{
    // Catches a neighbourhood of the wrong tiles or sizes (its own tile alone, tiles past the
    // frame's edge counted, partial tiles counted whole): a light is judged against the mean of
    // the wrong pixels and loses its sprite or gets one as part of a bright surface.
    const SceneAnalysis a = analyseLights();
    ASSERT_EQ(a.tileNeighbourhood.size(), cv::Size(5, 3));
    ASSERT_EQ(a.tileNeighbourhood.type(), CV_32FC4);
    const auto luminance = [](float b, float g, float r) { return 0.0722f * b + 0.7152f * g + 0.2126f * r; };
    const float grey = luminance(0.2f, 0.2f, 0.2f);
    // Tile (0, 0): tiles (0..1, 0..1), 32 x 32 px, one light (5, 5, 5) among them.
    const cv::Vec4f corner = a.tileNeighbourhood.at<cv::Vec4f>(0, 0);
    EXPECT_EQ(corner[0], 1024.0f);
    EXPECT_EQ(corner[1], 1.0f);
    EXPECT_NEAR(corner[2], 1023.0f * grey + 5.0f, 1e-2);
    // Tile (4, 2), the partial corner: tiles (3..4, 1..2), 16 + 11 px wide and 16 + 9 px high;
    // the light at (74, 40) only.
    const cv::Vec4f last = a.tileNeighbourhood.at<cv::Vec4f>(2, 4);
    EXPECT_EQ(last[0], 27.0f * 25.0f);
    EXPECT_EQ(last[1], 1.0f);
    EXPECT_NEAR(last[2], (27.0f * 25.0f - 1.0f) * grey + 20.0f, 1e-2);
    // Tile (2, 1), the middle: all nine tiles but the partial column 4, 48 x 41 px, with the
    // light at (17, 35), the pixel below white and (74, 40)'s column outside.
    const cv::Vec4f middle = a.tileNeighbourhood.at<cv::Vec4f>(1, 2);
    EXPECT_EQ(middle[0], 48.0f * 41.0f);
    EXPECT_EQ(middle[1], 1.0f);
    EXPECT_NEAR(middle[2], (48.0f * 41.0f - 2.0f) * grey + luminance(0.0f, 3.0f, 0.0f) + 0.99f, 1e-2);
}

TEST(SceneAnalysisMeasure, MatchesAPixelByPixelCount)
{
    // Catches a pixel in the wrong |CoC| bin, a tile's range, count or luminance from the wrong
    // pixels (measureScene() counts edges over row buffers and keeps a tile's sums in registers):
    // against the plain definition, pixel by pixel. 75 x 41 (partial tiles), random depths
    // 0.3-20 m, random colour with clipped and HDR pixels, 8-bit and float.
    cv::RNG rng(11);
    cv::Mat depth(41, 75, CV_32F);
    rng.fill(depth, cv::RNG::UNIFORM, 0.3, 20.0);
    LensSettings lens;
    lens.focusM = 2.0;
    lens.fNumber = 1.0;
    lens.maxCocPx = 40.0;
    const CocCoefficients k = cocCoefficients(lens, depth.cols);
    cv::Mat eightBit(depth.size(), CV_8UC3), linear(depth.size(), CV_32FC3);
    rng.fill(eightBit, cv::RNG::UNIFORM, 0, 256);
    rng.fill(linear, cv::RNG::UNIFORM, 0.0, 3.0);
    const auto luminance = [](float b, float g, float r) { return 0.0722f * b + 0.7152f * g + 0.2126f * r; };
    for (const cv::Mat& color : {eightBit, linear}) {
        const SceneMeasurement m = measureScene(depth, color, k);
        std::array<int, SceneAnalysis::kHistogramEdges.size() + 1> histogram{};
        cv::Mat lo(m.tiles, CV_32F, cv::Scalar(1e9)), hi(m.tiles, CV_32F, cv::Scalar(-1e9));
        cv::Mat highlights = cv::Mat::zeros(m.tiles, CV_32S);
        cv::Mat sums = cv::Mat::zeros(m.tiles, CV_64F);
        for (int y = 0; y < depth.rows; ++y)
            for (int x = 0; x < depth.cols; ++x) {
                const float z = depth.at<float>(y, x);
                const float c = std::abs(cocPixels(k, z));
                const auto& edges = SceneAnalysis::kHistogramEdges;
                ++histogram[static_cast<std::size_t>(std::upper_bound(edges.begin(), edges.end(), c) - edges.begin())];
                const cv::Point tile(x / 16, y / 16);
                lo.at<float>(tile) = std::min(lo.at<float>(tile), z);
                hi.at<float>(tile) = std::max(hi.at<float>(tile), z);
                float brightness = 0.0f;
                bool highlight = false;
                if (color.type() == CV_8UC3) {
                    const cv::Vec3b p = color.at<cv::Vec3b>(y, x);
                    brightness = luminance(srgbToLinear(p[0] / 255.0f), srgbToLinear(p[1] / 255.0f),
                                           srgbToLinear(p[2] / 255.0f));
                    highlight = std::max({p[0], p[1], p[2]}) >= 250;
                } else {
                    const cv::Vec3f p = color.at<cv::Vec3f>(y, x);
                    brightness = luminance(p[0], p[1], p[2]);
                    highlight = brightness > 1.0f;
                }
                highlights.at<int>(tile) += highlight ? 1 : 0;
                sums.at<double>(tile) += brightness;
            }
        EXPECT_EQ(m.histogram, histogram);
        EXPECT_EQ(cv::norm(m.tileMinDepth, lo, cv::NORM_INF), 0.0);
        EXPECT_EQ(cv::norm(m.tileMaxDepth, hi, cv::NORM_INF), 0.0);
        EXPECT_EQ(cv::norm(m.tileHighlights, highlights, cv::NORM_INF), 0.0);
        cv::Mat measured;
        m.tileLuminance.convertTo(measured, CV_64F);
        // Float sums of up to 256 pixels of up to 3 (about 400) against double ones: a float
        // rounding there is 3e-5, a tile's sum a few hundred of them at most.
        EXPECT_LT(cv::norm(measured, sums, cv::NORM_INF), 1e-2);
        EXPECT_EQ(m.highlightPixels, static_cast<std::size_t>(cv::sum(highlights)[0]));
    }
}

TEST(ScenePlan, TapLoopsUnrollWhereMostLinesRunToTheLastTap)
{
    // Four blurred tiles; a line is half the tile's largest |CoC| (and half that again at half
    // size). With 6 taps a line of 4.5 px or more counts as running to the last tap.
    SceneAnalysis analysis;
    analysis.tiles = {4, 1};
    analysis.tileMinCoc = (cv::Mat_<float>(1, 4) << 2.0f, 2.0f, 2.0f, -20.0f);
    analysis.tileMaxCoc = (cv::Mat_<float>(1, 4) << 9.0f, 9.0f, 4.0f, 3.0f);
    analysis.tileNearDiameter = cv::Mat::zeros(1, 4, CV_32F);
    analysis.minCoc = -20.0f;
    analysis.maxCoc = 9.0f;
    // Full size: lines of 4.5, 4.5, 2 and 10 px: three of four reach 4.5.
    EXPECT_TRUE(makePlan(analysis, false, HexagonKernel::RhombiSum, Resolution::Full, 6).unrolledTaps);
    // Half size: 2.25, 2.25, 1 and 5 px: one of four.
    EXPECT_FALSE(makePlan(analysis, false, HexagonKernel::RhombiSum, Resolution::Half, 6).unrolledTaps);
    // 12 taps want 9 px: only the near tile's 10 px.
    EXPECT_FALSE(makePlan(analysis, false, HexagonKernel::RhombiSum, Resolution::Full, 12).unrolledTaps);
    // The foreground reaching a tile lengthens its lines too (the near field).
    analysis.tileNearDiameter.setTo(20.0f);
    analysis.foreground = true;
    EXPECT_TRUE(makePlan(analysis, true, HexagonKernel::RhombiSum, Resolution::Full, 12).unrolledTaps);
    // McIntosh's passes have no such variant; no tap count, no decision.
    EXPECT_FALSE(makePlan(analysis, true, HexagonKernel::McIntoshMin, Resolution::Full, 6).unrolledTaps);
    EXPECT_FALSE(makePlan(analysis, true, HexagonKernel::RhombiSum, Resolution::Full).unrolledTaps);
}

// Defect: --explain reporting the gather's CoC (the lens' scaled to a round aperture's area, 1.1
// times as large for the circle) as the lens' blur.
TEST(ScenePlan, ExplainReportsTheLensCoc)
{
    SceneAnalysis analysis;
    analysis.tiles = {2, 1};
    analysis.minCoc = -44.0f;
    analysis.maxCoc = 5.5f;
    FramePlan plan;
    plan.kernel = HexagonKernel::RhombiSum;
    plan.blurTiles = {{0, 0}, {1, 0}};
    plan.gatherScale = 1.1f;
    const std::string text = plan.explain(analysis);
    EXPECT_NE(text.find("CoC -40.0..+5.0 px"), std::string::npos) << text;
}

} // namespace
} // namespace defocus
