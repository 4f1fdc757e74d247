// SPDX-License-Identifier: LGPL-2.1-or-later
// Resolution::Half: the blurs at half size, the output at the frame's size with its in-focus
// pixels kept (coc.frag HALF_SIZE, upscale_prefilter.frag, upscale.frag).
#include <array>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "filter/ColorSpace.hpp"
#include "filter/Lens.hpp"
#include "filter/Pipeline.hpp"
#include "filter/SceneAnalysis.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

class HalfSize : public test::GLTest {
protected:
    static QualitySettings quality(Resolution resolution)
    {
        QualitySettings q;
        q.kernel = HexagonKernel::RhombiSum;
        q.nearField = true;
        q.samples = 6;
        q.targetFormat = TargetFormat::Rgba32F;
        q.resolution = resolution;
        return q;
    }
    /// Half size with quarter size on large blur (off by default and in the presets).
    static QualitySettings quarterOnLargeBlur()
    {
        QualitySettings q = quality(Resolution::Half);
        q.quarterOnLargeBlur = true;
        return q;
    }

    /// Odd-sized on purpose: textured noise, the left part in focus (1 m), the right part at
    /// 2 m with a CoC of `farCocPx` (lensWithFarCoc).
    static Frame textured(cv::Size size, int focusColumns)
    {
        cv::Mat color(size, CV_8UC3);
        cv::RNG rng(7);
        rng.fill(color, cv::RNG::UNIFORM, 0, 256);
        cv::Mat depth(size, CV_32F, cv::Scalar(2.0f));
        depth.colRange(0, focusColumns).setTo(1.0f);
        return {color, depth, 0.0, 0, "textured"};
    }

    /// `out` (8-bit, the frame's size) keeps the frame's pixels in columns [0, keptColumns), to
    /// the bit in every channel, and has blurred `blurredColumns`: their standard deviation
    /// (the noise) below a third of the input's.
    static void expectKeptAndBlurred(const Frame& frame, const cv::Mat& out, int keptColumns,
                                     cv::Range blurredColumns)
    {
        cv::Mat sharp = cv::Mat::zeros(frame.color.size(), CV_8U);
        sharp.colRange(0, keptColumns).setTo(255);
        cv::Mat diff, anyChannel;
        cv::absdiff(out, frame.color, diff);
        cv::transform(diff, anyChannel, cv::Matx13f(1, 1, 1));
        EXPECT_EQ(cv::countNonZero(anyChannel & sharp), 0);
        cv::Scalar mean, stddevIn, stddevOut;
        cv::meanStdDev(frame.color.colRange(blurredColumns), mean, stddevIn);
        cv::meanStdDev(out.colRange(blurredColumns), mean, stddevOut);
        EXPECT_LT(stddevOut[0], stddevIn[0] / 3.0);
    }
};

TEST_F(HalfSize, OutputHasTheFrameSizeAndEveryViewToo)
{
    const Frame frame = textured({97, 61}, 40);
    Pipeline pipeline;
    const LensSettings lens = test::lensWithFarCoc(12.0);
    pipeline.process(frame, lens, quality(Resolution::Half));
    for (const View view : kAllViews) {
        const cv::Mat out = pipeline.read(view, Encoding::Linear32F);
        EXPECT_EQ(out.size(), frame.color.size()) << viewName(view);
        EXPECT_TRUE(test::allFinite(out)) << viewName(view);
    }
    // The intermediate targets are half size, rounded up.
    const cv::Mat input = pipeline.readTarget(View::Input);
    EXPECT_EQ(input.size(), cv::Size(49, 31));
    // Content: the input view shows each half-size texel as 2 x 2 pixels of its colour (linear
    // float both ways: to float rounding). Defect caught: a view that samples the half-size
    // target at the frame's coordinates (its top-left quarter stretched) or interpolates it.
    // PassesGLTest EveryViewShowsWhatItNames checks every view of the half-size presets.
    const cv::Mat view = pipeline.read(View::Input, Encoding::Linear32F);
    cv::Mat bgr, doubled;
    cv::cvtColor(input, bgr, cv::COLOR_RGBA2BGR);
    cv::resize(bgr, doubled, {}, 2, 2, cv::INTER_NEAREST);
    EXPECT_LE(cv::norm(view, doubled(cv::Rect({0, 0}, frame.color.size())), cv::NORM_INF), 1e-6);
}

/// The half-size input of `linear` (even size) on the CPU: each 2x2 block's mean, but on the
/// frame's border the mean of the block's border pixels only (the first or last row or column;
/// at a corner, the corner pixel), which the blurs repeat past the edge.
cv::Mat halfSizeWithBorders(const cv::Mat& linear)
{
    cv::Mat half;
    cv::resize(linear, half, linear.size() / 2, 0, 0, cv::INTER_AREA);
    const int lastX = half.cols - 1, lastY = half.rows - 1;
    for (int y = 0; y < half.rows; ++y)
        for (int x = 0; x < half.cols; ++x) {
            if (x != 0 && y != 0 && x != lastX && y != lastY)
                continue;
            const int x0 = x == lastX ? 2 * x + 1 : 2 * x, x1 = x == 0 ? 0 : 2 * x + 1;
            const int y0 = y == lastY ? 2 * y + 1 : 2 * y, y1 = y == 0 ? 0 : 2 * y + 1;
            cv::Vec3f sum(0, 0, 0);
            for (const int py : {y0, y1})
                for (const int px : {x0, x1})
                    sum += linear.at<cv::Vec3f>(py, px);
            half.at<cv::Vec3f>(y, x) = sum * 0.25f;
        }
    return half;
}

TEST_F(HalfSize, InputIsTheMeanOfEachBlockWithItsSharpestCoc)
{
    // 8-bit input: the mean is of linear light (sRGB decoded before the filtering). Both the
    // gather variant and the per-pixel one (with highlight recovery, which has no clipped
    // pixels to scale here: noise below 250) must give it: to 2e-3 against the exact curve on
    // the CPU (llvmpipe's sRGB decode measured 1.2e-3 off it, a third of an 8-bit step at the
    // top of the range), and to float rounding against each other. On the frame's border, the
    // mean of the border's pixels only (defect caught: a border texel holding its whole block,
    // which the blurs then repeat past the frame's edge with the row inside it mixed in).
    Frame frame = textured({64, 48}, 0);
    cv::min(frame.color, cv::Scalar::all(240), frame.color);
    frame.depth.colRange(0, 32).setTo(1.0f); // a depth edge inside no block: columns 31 | 32
    frame.depth.at<float>(10, 41) = 1.0f;     // one sharp pixel in a blurred block
    const LensSettings lens = test::lensWithFarCoc(12.0);
    const cv::Mat expected = halfSizeWithBorders(decodeSrgb(frame.color));
    cv::Mat first;
    for (const double gain : {1.0, 4.0}) {
        QualitySettings q = quality(Resolution::Half);
        q.highlightGain = gain;
        Pipeline pipeline;
        pipeline.process(frame, lens, q);
        const cv::Mat input = pipeline.readTarget(View::Input);
        cv::Mat rgba[4];
        cv::split(input, rgba);
        const cv::Mat channels[3] = {rgba[2], rgba[1], rgba[0]}; // the frame's BGR order
        cv::Mat bgr;
        cv::merge(channels, 3, bgr);
        double worst = 0.0;
        const cv::Mat error = cv::abs(bgr - expected);
        cv::minMaxLoc(error.reshape(1), nullptr, &worst);
        EXPECT_LT(worst, 2e-3) << "gain " << gain;
        if (first.empty())
            first = bgr;
        else
            EXPECT_LT(cv::norm(bgr, first, cv::NORM_INF), 1e-6);
        // CoC in half-size pixels: 0 left of the edge, 12 / 2 right of it, and 0 for the block
        // that holds the one sharp pixel.
        EXPECT_FLOAT_EQ(rgba[3].at<float>(3, 3), 0.0f);
        EXPECT_FLOAT_EQ(rgba[3].at<float>(3, 25), 6.0f);
        EXPECT_FLOAT_EQ(rgba[3].at<float>(5, 20), 0.0f);
    }
}

TEST_F(HalfSize, InFocusPixelsComeOutAsTheyWentIn)
{
    const Frame frame = textured({96, 64}, 48);
    Pipeline pipeline;
    const cv::Mat out = pipeline.run(frame, test::lensWithFarCoc(12.0), quality(Resolution::Half));
    // The upscale interpolates what the blur added, so an in-focus pixel within a pixel of a
    // blurred one may take a share of it; from two pixels away nothing may change, to the bit.
    // And the far part is blurred: most of its noise is gone.
    expectKeptAndBlurred(frame, out, 48 - 2, cv::Range(60, 96));
}

TEST_F(HalfSize, BlurMatchesTheFullSizeBlur)
{
    // Noise blurred by a 16-px hexagon at both sizes. Half size averages 2x2 pixels first and
    // interpolates after, so the two differ by a fraction of the blurred noise: 1.09 8-bit
    // levels of mean absolute difference measured on llvmpipe (the blurred noise itself has a
    // standard deviation of 5.3 levels). An upscale that samples one pixel off measured 1.71;
    // 1.4 catches that and leaves a third of a level for other drivers.
    const Frame frame = textured({128, 96}, 0);
    Pipeline pipeline;
    const LensSettings lens = test::lensWithFarCoc(16.0);
    const cv::Mat full = pipeline.run(frame, lens, quality(Resolution::Full), View::Composite, Encoding::Linear32F);
    const cv::Mat half = pipeline.run(frame, lens, quality(Resolution::Half), View::Composite, Encoding::Linear32F);
    const cv::Rect inside(16, 16, 96, 64); // away from the borders' clamp
    cv::Mat diff;
    cv::absdiff(encodeSrgb(full(inside)), encodeSrgb(half(inside)), diff);
    const cv::Scalar meanDiff = cv::mean(diff);
    EXPECT_LT((meanDiff[0] + meanDiff[1] + meanDiff[2]) / 3.0, 1.4);
}

TEST_F(HalfSize, FlatColourStaysFlatAndLightKeepsItsEnergy)
{
    // Far and blurred: a flat grey with one bright point (float input, HDR). The prefilter
    // passes flat areas unchanged, and the blur and the interpolation keep the sum of light;
    // the prefilter's clamp to its neighbourhood (no dark ring round a light) cuts its
    // undershoot, which adds a little: measured +1.8 % of the point's energy here (+1.9 % and
    // +1.6 % on black at 15 and 31 px). 3 % allowed; unclamped it was 0.03 %.
    cv::Mat color(64, 64, CV_32FC3, cv::Scalar::all(0.25f));
    color.at<cv::Vec3f>(32, 32) = cv::Vec3f(200.0f, 200.0f, 200.0f);
    const Frame frame{color, cv::Mat(64, 64, CV_32F, cv::Scalar(2.0f)), 0.0, 0, "point"};
    Pipeline pipeline;
    const cv::Mat out =
        pipeline.run(frame, test::lensWithFarCoc(12.0), quality(Resolution::Half), View::Composite, Encoding::Linear32F);
    const cv::Scalar in = cv::sum(color), result = cv::sum(out);
    EXPECT_NEAR(result[1], in[1], 0.03 * (200.0 - 0.25));
    // A corner far from the point: the grey, to float precision.
    const cv::Vec3f corner = out.at<cv::Vec3f>(4, 4);
    EXPECT_NEAR(corner[1], 0.25f, 1e-5f);
}

TEST(HalfSizePlan, DetailTilesAreTheTilesWithPixelsUnderTwoPixelsOfCoc)
{
    SceneAnalysis analysis;
    analysis.tiles = {3, 1};
    analysis.tileMinCoc = (cv::Mat_<float>(1, 3) << 0.0f, 1.9f, 2.0f);
    analysis.tileMaxCoc = (cv::Mat_<float>(1, 3) << 0.4f, 8.0f, 9.0f);
    analysis.tileNearDiameter = cv::Mat::zeros(1, 3, CV_32F);
    analysis.minCoc = 0.0f;
    analysis.maxCoc = 9.0f;
    const FramePlan half = makePlan(analysis, true, HexagonKernel::RhombiSum, Resolution::Half);
    ASSERT_EQ(half.detailTiles.size(), 2u);
    EXPECT_EQ(half.detailTiles[0], cv::Point(0, 0));
    EXPECT_EQ(half.detailTiles[1], cv::Point(1, 0));
    EXPECT_TRUE(makePlan(analysis, true, HexagonKernel::RhombiSum, Resolution::Full).detailTiles.empty());
}

TEST(HalfSizePlan, QuarterSizeWhenMoreThanATenthOfTheBlurredPixelsHaveAtLeast32PxOfCoc)
{
    // Defect caught: the wrong size chosen: quarter size for frames whose blur is small (at
    // 640x480 with the defaults, which must keep their half-size output), or half size for
    // those whose blur is large (1920x1080: the speed it buys); sharp pixels counted among the
    // blurred ones; the rule applied with quarterOnLargeBlur off or at full size.
    SceneAnalysis analysis;
    analysis.tiles = {1, 1};
    analysis.tileMinCoc = (cv::Mat_<float>(1, 1) << 0.0f);
    analysis.tileMaxCoc = (cv::Mat_<float>(1, 1) << 40.0f);
    analysis.tileNearDiameter = cv::Mat::zeros(1, 1, CV_32F);
    analysis.maxCoc = 40.0f;
    // Bins: < 0.5, < 1, < 2, < 4, < 8, < 16, < 32, < 64, the rest.
    const auto shiftFor = [&](std::array<int, 9> histogram, bool quarter = true,
                              Resolution resolution = Resolution::Half) {
        analysis.histogram = histogram;
        return makePlan(analysis, true, HexagonKernel::RhombiSum, resolution, 6, quarter).blurShift;
    };
    EXPECT_EQ(shiftFor({0, 0, 0, 0, 0, 0, 89, 11, 0}), 2);
    EXPECT_EQ(shiftFor({0, 0, 0, 0, 0, 0, 89, 0, 11}), 2);   // the last bin counts too
    EXPECT_EQ(shiftFor({0, 0, 0, 0, 0, 0, 90, 10, 0}), 1);   // a tenth is not more than a tenth
    EXPECT_EQ(shiftFor({0, 0, 0, 0, 0, 0, 100, 0, 0}), 1);   // 16-32 px: the 640x480 defaults' range
    EXPECT_EQ(shiftFor({900, 90, 0, 0, 0, 0, 0, 10, 0}), 2); // sharp pixels (< 1 px) are not counted
    EXPECT_EQ(shiftFor({0, 0, 900, 0, 0, 0, 0, 10, 0}), 1);  // 1-2 px is blurred
    EXPECT_EQ(shiftFor({0, 0, 0, 0, 0, 0, 0, 100, 0}, false), 1);
    EXPECT_EQ(shiftFor({0, 0, 0, 0, 0, 0, 0, 100, 0}, true, Resolution::Full), 0);
    // At quarter size the upscale keeps the frame's detail up to 4 px of CoC, so the tile
    // (CoC 0..40 px) is a detail tile, and so is one whose least CoC is 3 px; one from 5 px is not.
    analysis.histogram = {0, 0, 0, 0, 0, 0, 0, 100, 0};
    EXPECT_EQ(makePlan(analysis, true, HexagonKernel::RhombiSum, Resolution::Half, 6, true).detailTiles.size(), 1u);
    analysis.tileMinCoc.at<float>(0, 0) = 3.0f;
    EXPECT_EQ(makePlan(analysis, true, HexagonKernel::RhombiSum, Resolution::Half, 6, true).detailTiles.size(), 1u);
    analysis.tileMinCoc.at<float>(0, 0) = 5.0f;
    EXPECT_TRUE(makePlan(analysis, true, HexagonKernel::RhombiSum, Resolution::Half, 6, true).detailTiles.empty());
}

TEST_F(HalfSize, LargeBlurRunsAtQuarterSizeAndKeepsTheInFocusPixels)
{
    // Textured noise, the left 48 columns in focus, the rest at 40 px of CoC: quarter size.
    // Defects caught: the targets not a quarter of the frame (rounded up); in-focus pixels not
    // put back (the upscale's detail limit left at half size's 2 px would still keep them, but
    // an upscale that does not put the frame's pixels back, or samples D at the wrong place,
    // changes them); the far part not blurred.
    const Frame frame = textured({98, 66}, 48);
    Pipeline pipeline;
    const cv::Mat out = pipeline.run(frame, test::lensWithFarCoc(40.0), quarterOnLargeBlur());
    EXPECT_EQ(pipeline.plan().blurShift, 2);
    EXPECT_EQ(pipeline.readTarget(View::Input).size(), cv::Size(25, 17));
    ASSERT_EQ(out.size(), frame.color.size());
    // From four pixels (one quarter-size texel) away from the blurred part nothing may change.
    expectKeptAndBlurred(frame, out, 48 - 4, cv::Range(64, 98));
}

TEST_F(HalfSize, FramesWithBokehSpritesStayAtHalfSize)
{
    // Catches a frame with bokeh sprites blurred at quarter size: the rims of its lights'
    // hexagons, which the gather draws up to white, come out 4 px soft there (0.38 dB less in
    // the median of the corpus enlarged 3x, docs/benchmarks.md). The same float frame, all at
    // 40 px of CoC (quarter size without the light), with a light of 50 in its middle.
    cv::Mat color(128, 160, CV_32FC3, cv::Scalar::all(0.02));
    const cv::Mat depth(color.size(), CV_32F, cv::Scalar(2.0f));
    const LensSettings lens = test::lensWithFarCoc(40.0);
    QualitySettings q = quarterOnLargeBlur();
    q.highlightSprites = true;
    Pipeline pipeline;
    pipeline.process({color, depth, 0.0, 0, "dark"}, lens, q);
    EXPECT_EQ(pipeline.plan().blurShift, 2);
    color(cv::Rect(78, 62, 3, 3)).setTo(cv::Scalar::all(50.0));
    pipeline.process({color, depth, 0.0, 1, "light"}, lens, q);
    EXPECT_TRUE(pipeline.plan().highlightSprites);
    EXPECT_EQ(pipeline.plan().blurShift, 1);
}

TEST_F(HalfSize, QuarterSizeBlurMatchesTheHalfSizeBlur)
{
    // Noise blurred by a 40-px hexagon, at quarter size (the plan's choice) and at half size
    // (quarterOnLargeBlur off): what a clip shows when a frame crosses the rule. Defects caught:
    // a quarter-size result out of place (the upscale's coordinates at half size's scale, or
    // the CoC pass's blocks misaligned), or its CoC in the wrong unit (half-size pixels: a blur
    // twice as large); each a seam in time where a clip switches between the sizes. Measured on
    // llvmpipe: 0.42 8-bit levels of mean absolute difference; the upscale reading the quarter-
    // size result at half size's coordinates 2.73, the CoC in half-size pixels 1.42. 1.0 catches
    // both and leaves room for other drivers.
    const Frame frame = textured({160, 128}, 0);
    const LensSettings lens = test::lensWithFarCoc(40.0);
    Pipeline quarterPipeline, halfPipeline;
    const QualitySettings halfOnly = quality(Resolution::Half);
    const cv::Mat quarter = quarterPipeline.run(frame, lens, quarterOnLargeBlur(), View::Composite, Encoding::Linear32F);
    const cv::Mat half = halfPipeline.run(frame, lens, halfOnly, View::Composite, Encoding::Linear32F);
    ASSERT_EQ(quarterPipeline.plan().blurShift, 2);
    ASSERT_EQ(halfPipeline.plan().blurShift, 1);
    const cv::Rect inside(24, 24, 112, 80); // away from the borders' repeated edge
    cv::Mat diff;
    cv::absdiff(encodeSrgb(quarter(inside)), encodeSrgb(half(inside)), diff);
    const cv::Scalar meanDiff = cv::mean(diff);
    EXPECT_LT((meanDiff[0] + meanDiff[1] + meanDiff[2]) / 3.0, 1.0);
}

} // namespace
} // namespace defocus
