// The McIntosh passes checked analytically on llvmpipe: zero CoC is the identity, a point light
// becomes a hexagon of the predicted size and orientation, constant depth blurs uniformly.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "filter/ColorSpace.hpp"
#include "filter/Lens.hpp"
#include "filter/Pipeline.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

class Passes : public test::GLTest {};

TEST_F(Passes, ZeroCocReturnsTheInput)
{
    cv::Mat color(97, 131, CV_8UC3);
    cv::randu(color, 0, 256);
    Frame frame{color, cv::Mat(color.size(), CV_32F, cv::Scalar(3.0f)), 0.0, 0, "noise"};
    LensSettings lens;
    lens.focusM = 3.0; // every pixel on the focus plane
    Pipeline pipeline;
    const cv::Mat out = pipeline.run(frame, lens, {});
    double maxDiff = 0;
    cv::minMaxLoc(cv::abs(out - color), nullptr, &maxDiff);
    // sRGB decode -> half float -> sRGB encode: half's 11-bit mantissa may move a value by one
    // 8-bit step, never more.
    EXPECT_LE(maxDiff, 1.0);
    cv::Mat coc = pipeline.readTarget(View::Input);
    std::vector<cv::Mat> channels;
    cv::split(coc, channels);
    EXPECT_EQ(cv::countNonZero(cv::abs(channels[3]) > 1e-3), 0);
}

TEST_F(Passes, PointLightBecomesAFlatTopHexagonOfThePredictedArea)
{
    // One bright pixel on black, all at the same far depth: the gather of every pixel is the
    // scatter of the light, so the output is the aperture shape itself.
    const int size = 121;
    const double diameter = 40.0; // vertex-to-vertex width of the hexagon, pixels
    cv::Mat color(size, size, CV_32FC3, cv::Scalar::all(0.0));
    color.at<cv::Vec3f>(size / 2, size / 2) = cv::Vec3f(1000.0f, 1000.0f, 1000.0f);
    Frame frame{color, cv::Mat(color.size(), CV_32F, cv::Scalar(2.0f)), 0.0, 0, "point"};
    QualitySettings quality;
    quality.samples = 48; // taps under one pixel apart, so the 1-px light is never skipped
    quality.targetFormat = TargetFormat::Rgba32F;
    Pipeline pipeline;
    const cv::Mat out = pipeline.run(frame, test::lensWithFarCoc(diameter), quality, View::Composite, Encoding::Linear32F);
    cv::Mat gray;
    cv::cvtColor(out, gray, cv::COLOR_BGR2GRAY);

    // Plateau level: the median of the inner disc (radius 0.3 d is inside the hexagon).
    std::vector<float> inner;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x)
            if (std::hypot(x - size / 2, y - size / 2) < 0.3 * diameter)
                inner.push_back(gray.at<float>(y, x));
    std::nth_element(inner.begin(), inner.begin() + static_cast<long>(inner.size() / 2), inner.end());
    const float plateau = inner[inner.size() / 2];
    ASSERT_GT(plateau, 0.0f);

    // Area at half the plateau: the soft edges (bilinear taps) are symmetric about it.
    const cv::Mat lit = gray > 0.5f * plateau;
    const double area = cv::countNonZero(lit);
    const double predicted = 3.0 * std::sqrt(3.0) / 8.0 * diameter * diameter; // regular hexagon
    EXPECT_NEAR(area, predicted, 0.10 * predicted) << "hexagon area";

    // Flat top and bottom: the top and bottom lit rows are about half a diameter wide (a
    // pointy-top hexagon would have a few pixels there).
    cv::Rect box = cv::boundingRect(lit);
    const int topWidth = cv::countNonZero(lit.row(box.y));
    const int bottomWidth = cv::countNonZero(lit.row(box.y + box.height - 1));
    EXPECT_GT(topWidth, 0.35 * diameter);
    EXPECT_GT(bottomWidth, 0.35 * diameter);
    // Height of a flat-top hexagon is sqrt(3)/2 of its width; one pixel of edge softness allowed.
    EXPECT_NEAR(box.width, diameter, 2.0);
    EXPECT_NEAR(box.height, std::sqrt(3.0) / 2.0 * diameter, 2.0);

    // Nothing outside: every pixel brighter than 1 % of the plateau lies inside the hexagon
    // grown by 1.5 px (the reach of a bilinear tap).
    const double c = size / 2, r = diameter / 2 + 1.5;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            if (gray.at<float>(y, x) <= 0.01f * plateau)
                continue;
            const double dx = std::abs(x - c), dy = std::abs(y - c);
            const bool inside = dy <= std::sqrt(3.0) / 2.0 * r && std::sqrt(3.0) * dx + dy <= std::sqrt(3.0) * r;
            EXPECT_TRUE(inside) << "light at (" << x << ", " << y << ")";
        }
}

TEST_F(Passes, ConstantDepthBlursUniformly)
{
    // A fine checkerboard blurred far wider than its period is flat grey everywhere away from
    // the borders, and the CoC target is the same diameter everywhere.
    cv::Mat color(160, 200, CV_32FC3);
    for (int y = 0; y < color.rows; ++y)
        for (int x = 0; x < color.cols; ++x)
            color.at<cv::Vec3f>(y, x) = cv::Vec3f::all(((x / 2 + y / 2) % 2) ? 1.0f : 0.0f);
    Frame frame{color, cv::Mat(color.size(), CV_32F, cv::Scalar(2.0f)), 0.0, 0, "checker"};
    Pipeline pipeline;
    const cv::Mat out = pipeline.run(frame, test::lensWithFarCoc(24.0), {}, View::Composite, Encoding::Linear32F);
    const cv::Rect interior(30, 30, color.cols - 60, color.rows - 60);
    cv::Scalar mean, stddev;
    cv::meanStdDev(out(interior), mean, stddev);
    double lo = 0, hi = 0;
    cv::minMaxLoc(out(interior).reshape(1), &lo, &hi);
    // min(A, B) of two averages of a 50 % pattern: a little under 0.5, the same everywhere.
    EXPECT_NEAR(mean[0], 0.5, 0.06);
    EXPECT_LT(hi - lo, 0.08) << "the blur must not vary across the frame";
    std::vector<cv::Mat> channels;
    cv::split(pipeline.readTarget(View::Input), channels);
    cv::minMaxLoc(channels[3], &lo, &hi);
    EXPECT_NEAR(lo, 24.0, 1e-2);
    EXPECT_NEAR(hi, 24.0, 1e-2);
}

TEST_F(Passes, CocTargetIsSignedNearNegativeFarPositive)
{
    cv::Mat color(20, 40, CV_8UC3, cv::Scalar::all(128));
    cv::Mat depth(color.size(), CV_32F, cv::Scalar(1.0f));
    depth(cv::Rect(20, 0, 20, 20)).setTo(8.0f);
    LensSettings lens;
    lens.focusM = 2.0;
    lens.maxCocPx = 512.0;
    Pipeline pipeline;
    pipeline.run({color, depth, 0.0, 0, "split"}, lens, {}, View::Composite);
    std::vector<cv::Mat> channels;
    cv::split(pipeline.readTarget(View::Input), channels);
    const auto k = cocCoefficients(lens, color.cols);
    // RGBA16F alpha: half precision, 11 bits, on values of a few pixels.
    EXPECT_NEAR(channels[3].at<float>(10, 5), cocPixels(k, 1.0f), 5e-3);
    EXPECT_NEAR(channels[3].at<float>(10, 30), cocPixels(k, 8.0f), 5e-3);
    EXPECT_LT(channels[3].at<float>(10, 5), 0.0f);
    EXPECT_GT(channels[3].at<float>(10, 30), 0.0f);
}

TEST_F(Passes, HdrEnergyIsKeptThroughTheLinearPath)
{
    // Scene-linear input far above 1: a blurred constant field stays at its value (a convex
    // combination of equal values), and a bright square keeps its total energy within the
    // hexagon-vs-rhombus loss of the min() composite.
    cv::Mat color(64, 64, CV_32FC3, cv::Scalar::all(50.0));
    Pipeline pipeline;
    cv::Mat out = pipeline.run({color, cv::Mat(color.size(), CV_32F, cv::Scalar(2.0f)), 0.0, 0, "hdr"},
                               test::lensWithFarCoc(12.0), {}, View::Composite, Encoding::Linear32F);
    double lo = 0, hi = 0;
    cv::minMaxLoc(out.reshape(1), &lo, &hi);
    // Half-float targets hold 50 to 11 bits: 50 * 2^-11 = 0.025.
    EXPECT_NEAR(lo, 50.0, 0.05);
    EXPECT_NEAR(hi, 50.0, 0.05);

    color.setTo(cv::Scalar::all(0.0));
    color(cv::Rect(28, 28, 8, 8)).setTo(cv::Scalar::all(1e4));
    out = pipeline.run({color, cv::Mat(color.size(), CV_32F, cv::Scalar(2.0f)), 0.0, 0, "hdr"},
                       test::lensWithFarCoc(12.0), {}, View::Composite, Encoding::Linear32F);
    const double energyIn = cv::sum(color)[0], energyOut = cv::sum(out)[0];
    EXPECT_GT(energyOut, 0.6 * energyIn);
    EXPECT_LE(energyOut, 1.01 * energyIn);
    cv::minMaxLoc(out.reshape(1), nullptr, &hi);
    EXPECT_GT(hi, 1000.0) << "the highlight stays HDR, it is not clipped to 1";
}

TEST_F(Passes, AFrameInFocusDoesNotLeaveTheNextFrameUnblurred)
{
    // The all-in-focus shortcut is decided per frame: a blurry frame after a sharp one is blurred.
    cv::Mat color(48, 64, CV_8UC3);
    cv::randu(color, 0, 256);
    LensSettings lens;
    lens.focusM = 2.0;
    Pipeline pipeline;
    const cv::Mat sharp = pipeline.run({color, cv::Mat(color.size(), CV_32F, cv::Scalar(2.0f)), 0.0, 0, "sharp"}, lens, {});
    EXPECT_TRUE(pipeline.plan().allInFocus);
    EXPECT_EQ(cv::norm(sharp, color, cv::NORM_INF), 0.0);
    const cv::Mat blurred =
        pipeline.run({color, cv::Mat(color.size(), CV_32F, cv::Scalar(0.3f)), 0.0, 1, "near"}, lens, {});
    EXPECT_FALSE(pipeline.plan().allInFocus);
    EXPECT_GT(cv::norm(blurred, color, cv::NORM_L1) / static_cast<double>(color.total() * 3), 5.0)
        << "noise blurred by a large CoC moves pixels by tens of levels on average";
}

TEST_F(Passes, EveryViewRendersAtTheFrameSize)
{
    cv::Mat color(48, 200, CV_8UC3, cv::Scalar(20, 120, 220));
    cv::Mat depth(color.size(), CV_32F, cv::Scalar(4.0f));
    Pipeline pipeline;
    pipeline.process({color, depth, 0.0, 0, "views"}, {}, {});
    for (const View view : kAllViews) {
        const cv::Mat image = pipeline.read(view, Encoding::Srgb8);
        EXPECT_EQ(image.size(), color.size()) << viewName(view);
        EXPECT_EQ(image.type(), CV_8UC3) << viewName(view);
    }
}

} // namespace
} // namespace defocus
