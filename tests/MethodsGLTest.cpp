// SPDX-License-Identifier: LGPL-2.1-or-later
// The methods of the registry checked analytically on llvmpipe: zero CoC returns the input, flat
// colour stays flat under any blur, bad input gives no NaN/Inf; the CPU reference turns a point
// light into a hexagon of the predicted area and orientation, conserves energy, and beats every
// GPU method against the path-traced truth of the Blender scene.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "bench/Metrics.hpp"
#include "bench/methods/Method.hpp"
#include "bench/methods/Presets.hpp"
#include "bench/methods/ReferenceScatter.hpp"
#include "filter/ColorSpace.hpp"
#include "filter/Presets.hpp"
#include "sources/ImageIO.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

class Methods : public test::GLTest {};

std::vector<const MethodInfo*> gpuMethods()
{
    std::vector<const MethodInfo*> list;
    for (const MethodInfo& info : methodRegistry())
        if (info.gpu)
            list.push_back(&info);
    return list;
}

/// The method's own sample count (McIntosh: the default 16).
MethodSettings settingsFor(const MethodInfo& info, Resolution resolution, TargetFormat precision)
{
    const int samples = info.samples.size() == 1 ? info.samples.front() : QualitySettings{}.samples;
    return {samples, resolution, precision};
}

/// Runs every GPU method on `frame` at both resolutions and both precisions and hands each
/// linear output to `check(info, settings, output)`.
template <typename Check>
void forEveryGpuSetting(const Frame& frame, const LensSettings& lens, Check check)
{
    for (const MethodInfo* info : gpuMethods()) {
        auto method = createMethod(info->name);
        for (const Resolution resolution : {Resolution::Full, Resolution::Half})
            for (const TargetFormat precision : {TargetFormat::Rgba16F, TargetFormat::Rgba32F}) {
                const MethodSettings settings = settingsFor(*info, resolution, precision);
                check(*info, settings, method->run(frame, lens, settings).linear);
            }
    }
}

TEST_F(Methods, RegistryNamesAreUniqueAndCreatable)
{
    for (const MethodInfo& info : methodRegistry()) {
        EXPECT_EQ(findMethod(info.name), &info);
        ASSERT_FALSE(info.samples.empty()) << info.name;
        for (const int samples : info.samples) {
            EXPECT_GE(samples, info.minSamples) << info.name;
            EXPECT_LE(samples, info.maxSamples) << info.name;
        }
        EXPECT_EQ(createMethod(info.name)->info().name, info.name);
    }
    EXPECT_EQ(findMethod("bokeh"), nullptr);
    EXPECT_THROW(createMethod("bokeh"), std::invalid_argument);
}

// Zero CoC returns the input, through each method's passes: the pipeline methods' plan would
// return the input before any pass runs, so it is off here. Defect caught: a method whose passes
// move a pixel with CoC 0. Signed differences: 8-bit subtraction saturates at 0 and would hide
// every pixel that came out darker.
TEST_F(Methods, ZeroCocReturnsTheInput)
{
    cv::Mat color(97, 131, CV_8UC3);
    cv::randu(color, 0, 256);
    const Frame frame{color, cv::Mat(color.size(), CV_32F, cv::Scalar(3.0f)), 0.0, 0, "noise"};
    LensSettings lens;
    lens.focusM = 3.0; // every pixel on the focus plane
    for (const MethodInfo* info : gpuMethods()) {
        auto method = createMethod(info->name);
        for (const TargetFormat precision : {TargetFormat::Rgba16F, TargetFormat::Rgba32F}) {
            MethodSettings settings = settingsFor(*info, Resolution::Full, precision);
            settings.adaptive = false;
            const MethodResult result = method->run(frame, lens, settings);
            ASSERT_EQ(result.linear.type(), CV_32FC3);
            ASSERT_EQ(result.linear.size(), color.size());
            cv::Mat difference;
            cv::subtract(encodeSrgb(result.linear), color, difference, cv::noArray(), CV_16S);
            double lo = 0, hi = 0;
            cv::minMaxLoc(difference.reshape(1), &lo, &hi);
            // sRGB decode -> (half) float -> sRGB encode may move a value by one 8-bit step, no more.
            EXPECT_GE(lo, -1.0) << describe(*info, settings);
            EXPECT_LE(hi, 1.0) << describe(*info, settings);
            EXPECT_GT(result.wallMs, 0.0);
        }
    }
}

TEST_F(Methods, FlatColourStaysFlatUnderBlur)
{
    // One colour everywhere, depth in blocks from 0.6 m to 12 m: every pixel blurs, by CoCs from
    // tens of pixels in front to several behind, but averages of one colour are that colour.
    const cv::Vec3f flat(0.2f, 0.5f, 0.8f);
    cv::Mat color(120, 160, CV_32FC3, cv::Scalar(flat[0], flat[1], flat[2]));
    cv::Mat depth(color.size(), CV_32F);
    for (int y = 0; y < depth.rows; ++y)
        for (int x = 0; x < depth.cols; ++x)
            depth.at<float>(y, x) = 0.6f + 1.1f * static_cast<float>(((x / 17) * 7 + (y / 13) * 3) % 11);
    const Frame frame{color, depth, 0.0, 0, "flat"};
    LensSettings lens;
    lens.focusM = 2.0;
    lens.fNumber = 1.4;
    forEveryGpuSetting(frame, lens, [&](const MethodInfo& info, const MethodSettings& settings, const cv::Mat& out) {
        cv::Mat diff;
        cv::absdiff(out, cv::Scalar(flat[0], flat[1], flat[2]), diff);
        double maxDiff = 0;
        cv::minMaxLoc(diff.reshape(1), nullptr, &maxDiff);
        // Half float keeps 11 significant bits: 0.8 is held to within 2^-11 * 0.8 = 4e-4,
        // and a weighted average of such values stays within a few of those steps.
        const double tolerance = settings.precision == TargetFormat::Rgba16F ? 2e-3 : 1e-5;
        EXPECT_LE(maxDiff, tolerance) << describe(info, settings);
    });
}

TEST_F(Methods, BadInputGivesNoNanOrInf)
{
    // HDR colour with NaN, +-Inf and huge values; depth with holes of every kind.
    cv::Mat color(64, 96, CV_32FC3);
    cv::randu(color, 0.0f, 50.0f);
    color.at<cv::Vec3f>(10, 10) = cv::Vec3f(std::nanf(""), 1.0f, 1.0f);
    color.at<cv::Vec3f>(20, 30) = cv::Vec3f(std::numeric_limits<float>::infinity(), 0.0f, 1e30f);
    color.at<cv::Vec3f>(40, 50) = cv::Vec3f(-std::numeric_limits<float>::infinity(), 3e38f, -5.0f);
    cv::Mat depth(color.size(), CV_32F);
    cv::randu(depth, 0.5f, 20.0f);
    depth(cv::Rect(0, 0, 20, 20)).setTo(0.0f);
    depth.at<float>(30, 30) = std::nanf("");
    depth.at<float>(31, 31) = std::numeric_limits<float>::infinity();
    const Frame frame{color, depth, 0.0, 0, "bad"};
    LensSettings lens;
    lens.focusM = 2.0;
    lens.fNumber = 1.4;
    forEveryGpuSetting(frame, lens, [](const MethodInfo& info, const MethodSettings& settings, const cv::Mat& out) {
        EXPECT_TRUE(test::allFinite(out)) << describe(info, settings);
    });
    auto reference = createMethod("reference");
    EXPECT_TRUE(test::allFinite(reference->run(frame, lens, {}).linear));
}

TEST_F(Methods, ReferenceTurnsAPointLightIntoAHexagonOfThePredictedAreaAndKeepsItsEnergy)
{
    const int size = 121;
    const double diameter = 40.0; // vertex-to-vertex width of the hexagon, pixels
    const float light = 1000.0f;
    cv::Mat color(size, size, CV_32FC3, cv::Scalar::all(0.0));
    color.at<cv::Vec3f>(size / 2, size / 2) = cv::Vec3f(light, light, light);
    const Frame frame{color, cv::Mat(color.size(), CV_32F, cv::Scalar(2.0f)), 0.0, 0, "point"};
    const cv::Mat out = createMethod("reference")->run(frame, test::lensWithFarCoc(diameter), {}).linear;
    cv::Mat gray;
    cv::cvtColor(out, gray, cv::COLOR_BGR2GRAY);

    // Energy: the hexagon lies inside the image, so the light is all there.
    const double sum = cv::sum(gray)[0];
    EXPECT_NEAR(sum, light, 0.01 * light);

    // Area: every fully covered pixel holds light / area, so sum / plateau is the area.
    const double predicted = 3.0 * std::numbers::sqrt3 / 8.0 * diameter * diameter;
    const double plateau = gray.at<float>(size / 2, size / 2);
    ASSERT_GT(plateau, 0.0);
    EXPECT_NEAR(sum / plateau, predicted, 0.05 * predicted);
    EXPECT_NEAR(plateau, light / predicted, 1e-3 * light / predicted);

    // Orientation: flat top and bottom, so the centre row spans the full diameter and the centre
    // column only the height between the flat edges, d * sqrt(3) / 2.
    const int wide = cv::countNonZero(gray.row(size / 2) > 0.0f);
    const int tall = cv::countNonZero(gray.col(size / 2) > 0.0f);
    EXPECT_NEAR(wide, diameter, 2.0);
    EXPECT_NEAR(tall, diameter * std::numbers::sqrt3 / 2.0, 2.0);

    // "reference-pointy" turns the same hexagon by 30 (= 90) degrees: a corner on top, as Cycles
    // renders and as the scatter's and the lens's blade rotation 0 give.
    cv::Mat pointy;
    cv::cvtColor(createMethod("reference-pointy")->run(frame, test::lensWithFarCoc(diameter), {}).linear, pointy,
                 cv::COLOR_BGR2GRAY);
    EXPECT_NEAR(cv::sum(pointy)[0], light, 0.01 * light);
    EXPECT_NEAR(cv::countNonZero(pointy.row(size / 2) > 0.0f), diameter * std::numbers::sqrt3 / 2.0, 2.0);
    EXPECT_NEAR(cv::countNonZero(pointy.col(size / 2) > 0.0f), diameter, 2.0);

    // The exact overlap itself: a hexagon far larger than a pixel covers an inner pixel fully,
    // and the overlaps of all pixels add up to its area.
    ScatterOptions flatTop;
    flatTop.rotationDeg = 30.0f;
    EXPECT_NEAR(polygonSquareOverlap(flatTop, 0.0, 0.0, 10.0, -0.5, -0.5), 1.0, 1e-12);
    double total = 0.0;
    for (int y = -5; y < 5; ++y)
        for (int x = -5; x < 5; ++x)
            total += polygonSquareOverlap(flatTop, 0.3, -0.2, 3.7, x, y);
    EXPECT_NEAR(total, 3.0 * std::numbers::sqrt3 / 2.0 * 3.7 * 3.7, 1e-9);
}

TEST_F(Methods, ReferenceBeatsThePublishedMethodsAndTheRhombiMatchIt)
{
    const auto dir = test::dataDir() / "blender_spheres";
    const cv::Mat color = readColor(dir / "color_linear.exr");
    const cv::Mat depth = readDepth(dir / "depth.exr", 1000.0);
    const cv::Mat truth = readColor(dir / "truth_f1.4_focus5_linear.exr");
    ASSERT_EQ(color.size(), cv::Size(640, 480));
    const Frame frame{color, depth, 0.0, 0, "blender"};
    const LensSettings lens = blenderSpheresLens();

    // The reference runs at full size: it took 4-17 s for 640x480 on the 2-core development
    // machine (depending on other load), inside the 30 s this test allows it.
    const auto start = std::chrono::steady_clock::now();
    // The reference with the truth's orientation (a corner on top, like the GPU methods by
    // default): the flat-topped one measured 34.57 dB, which the rhombi with their near field
    // come within 0.2 dB of.
    const MethodResult reference = createMethod("reference-pointy")->run(frame, lens, {});
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double referenceDb = psnrLinear(reference.linear, truth);
    std::printf("[ FIGURE   ] reference: %.2f dB in %.1f s\n", referenceDb, seconds);
    for (const MethodInfo* info : gpuMethods()) {
        const MethodSettings settings = settingsFor(*info, Resolution::Full, TargetFormat::Rgba16F);
        const double db = psnrLinear(createMethod(info->name)->run(frame, lens, settings).linear, truth);
        std::printf("[ FIGURE   ] %s: %.2f dB\n", describe(*info, settings).c_str(), db);
        // The published gathers stay under the best a single layer scattered exactly gives. The
        // rhombi with their near field and bokeh sprites went past it (36.4 dB against 35.6
        // when this was written: the sprites' edges are as exact as the reference's, and the
        // near field spreads foreground over what lies behind it, which the reference's
        // depth-ordered layers cover instead): at least within 0.2 dB of it, for other drivers.
        if (info->name == "rhombi-near") {
            EXPECT_GT(db, referenceDb - 0.2) << describe(*info, settings);
        } else if (!info->name.starts_with("rhombi")) {
            EXPECT_GT(referenceDb, db) << describe(*info, settings);
        }
    }
    // Its figure when this test was written: 35.55 dB (Blender's Defocus node: 32.9 dB). A
    // margin of 1 dB for other drivers' rounding; the data is fixed.
    EXPECT_GT(referenceDb, 34.5);
}

TEST(Presets, AreKnownSettings)
{
    for (const Preset& p : presets()) {
        const MethodInfo* info = findMethod(p.method);
        ASSERT_NE(info, nullptr) << p.name;
        EXPECT_GE(p.settings.samples, info->minSamples);
        EXPECT_LE(p.settings.samples, info->maxSamples);
        QualitySettings quality = presetSettings(p.name);
        EXPECT_TRUE(validate(quality).empty()) << p.name;
    }
    EXPECT_NO_THROW(preset(kDefaultPreset));
    EXPECT_THROW(preset("ultra"), std::invalid_argument);
}

} // namespace
} // namespace defocus
