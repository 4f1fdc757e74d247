// SPDX-License-Identifier: LGPL-2.1-or-later
// Lens maths without GL: thin-lens CoC values, signs, the madd derivation, the focal-range model.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "bench/methods/Method.hpp"
#include "filter/Lens.hpp"
#include "filter/passes/HexBlurPass.hpp"

namespace defocus {
namespace {

// The Blender scene of data/blender_spheres: 85 mm, f/1.4, focus 5 m, 36 mm over 640 px.
/// The Blender scene's camera with max-coc at its limit, so that no figure below is clamped,
/// and the sensor at the image distance, as the scene's documented figures have it.
LensSettings blenderLens()
{
    LensSettings lens = blenderSpheresLens();
    lens.maxCocPx = 512.0;
    lens.fieldOfView = FieldOfView::ImageDistance;
    return lens;
}

TEST(Lens, ZeroAtFocusAndSignChangesAcrossIt)
{
    const auto k = cocCoefficients(blenderLens(), 640);
    // float32 madd of two ~1e3 px terms that cancel: a few 1e-4 px of rounding.
    EXPECT_NEAR(cocPixels(k, 5.0f), 0.0f, 1e-3f);
    EXPECT_LT(cocPixels(k, 4.9f), 0.0f);
    EXPECT_GT(cocPixels(k, 5.1f), 0.0f);
}

TEST(Lens, MatchesBlenderSceneFigures)
{
    // Figures from the scene's documentation (thin lens at 640 px), tolerance 0.2 px as the
    // issue asks; they are quoted to 0.1 px.
    const auto k = cocCoefficients(blenderLens(), 640);
    EXPECT_NEAR(std::abs(cocPixels(k, 1.43f)), 46.6f, 0.2f);
    EXPECT_NEAR(cocPixels(k, 8.0f), 7.0f, 0.2f);
    EXPECT_NEAR(cocPixels(k, 30.0f), 15.6f, 0.2f);
    EXPECT_NEAR(std::abs(cocPixels(k, 2.2f)), 23.8f, 0.2f);
    EXPECT_NEAR(cocPixels(k, 20.0f), 14.0f, 0.2f);
    EXPECT_LT(cocPixels(k, 1.43f), 0.0f) << "near blur is negative";
}

TEST(Lens, MaddEqualsTextbookFormula)
{
    const auto lens = blenderLens();
    const auto k = cocCoefficients(lens, 640);
    for (double z = 0.2; z < 100.0; z *= 1.3) {
        const double expected = thinLensCocPixels(lens, 640, z);
        // float32 evaluation: relative 1e-5 of the two terms (~1000 px at 0.2 m).
        EXPECT_NEAR(cocPixels(k, static_cast<float>(z)), std::clamp(expected, -512.0, 512.0), 2e-2) << "z=" << z;
    }
}

TEST(Lens, FieldOfViewFromTheFocalLengthScalesTheCocBySMinusFOverS)
{
    // A renderer's camera (the sensor width fitted at f, not at v = f S / (S - f)) sees the
    // same blur on the focus plane at f / v = (S - f) / S of the pixels: 0.983 at 85 mm
    // focused at 5 m, what docs/synthetic.md measured on the Cycles truth (0.980).
    LensSettings image = blenderLens();
    LensSettings focal = image;
    focal.fieldOfView = FieldOfView::FocalLength;
    const auto ki = cocCoefficients(image, 640), kf = cocCoefficients(focal, 640);
    const double scale = (5.0 - 0.085) / 5.0;
    for (const float z : {1.43f, 3.0f, 8.0f, 30.0f}) {
        // Relative 1e-5 of float32 over the two cancelling terms.
        EXPECT_NEAR(cocPixels(kf, z), scale * cocPixels(ki, z), 2e-3) << "z=" << z;
        EXPECT_NEAR(cocPixels(kf, z), thinLensCocPixels(focal, 640, z), 2e-2) << "z=" << z;
    }
    EXPECT_NEAR(cocPixels(kf, 5.0f), 0.0f, 1e-3f);
    // At infinity the sensor sits at f either way: no difference.
    image.focusM = focal.focusM = std::numeric_limits<double>::infinity();
    EXPECT_FLOAT_EQ(cocPixels(cocCoefficients(focal, 640), 10.0f), cocPixels(cocCoefficients(image, 640), 10.0f));
}

TEST(Lens, ClampsToMaxCoc)
{
    auto lens = blenderLens();
    lens.maxCocPx = 10.0; // the far limit of this lens is 18.7 px, the near one unbounded
    const auto k = cocCoefficients(lens, 640);
    EXPECT_FLOAT_EQ(cocPixels(k, 1.43f), -10.0f);
    EXPECT_FLOAT_EQ(cocPixels(k, 1e6f), 10.0f);
}

TEST(Lens, FocusAtInfinityPutsEverythingInFront)
{
    auto lens = blenderLens();
    lens.focusM = std::numeric_limits<double>::infinity();
    const auto k = cocCoefficients(lens, 640);
    EXPECT_LT(cocPixels(k, 10.0f), 0.0f);
    EXPECT_NEAR(cocPixels(k, 1e9f), 0.0f, 1e-3f);
    // c = A f / z in pixels: 0.0607 m * 0.085 m / 10 m * 640 / 0.036 m
    EXPECT_NEAR(cocPixels(k, 10.0f), -0.085 / 1.4 * 0.085 / 10.0 * 640.0 / 0.036, 1e-3);
}

TEST(Lens, FocalRangeRisesLinearlyToTheLimits)
{
    LensSettings lens;
    lens.model = CocModel::FocalRange;
    lens.focusM = 3.0;
    lens.nearLimitM = 1.0;
    lens.farLimitM = 7.0;
    lens.maxCocPx = 16.0;
    const auto k = cocCoefficients(lens, 640);
    EXPECT_NEAR(cocPixels(k, 3.0f), 0.0f, 1e-5f);
    EXPECT_NEAR(cocPixels(k, 2.0f), -8.0f, 1e-4f);
    EXPECT_NEAR(cocPixels(k, 1.0f), -16.0f, 1e-4f);
    EXPECT_NEAR(cocPixels(k, 5.0f), 8.0f, 1e-4f);
    EXPECT_NEAR(cocPixels(k, 7.0f), 16.0f, 1e-4f);
    EXPECT_FLOAT_EQ(cocPixels(k, 50.0f), 16.0f);
}

TEST(HexBlurOffsets, SpanTheDiameterSymmetricallyWithSquarePixels)
{
    const int width = 640, height = 480;
    const auto taps = HexBlurPass::offsets(0.0f, 16, width, height);
    ASSERT_EQ(taps.size(), 16u);
    EXPECT_NEAR(taps.front().x * width, -0.5f, 1e-6f);
    EXPECT_NEAR(taps.back().x * width, 0.5f, 1e-6f);
    for (const auto& t : taps)
        EXPECT_FLOAT_EQ(t.y, 0.0f);
    // At 120 degrees a tap's length in pixels is still half a diameter: no stretch by aspect.
    const auto diagonal = HexBlurPass::offsets(120.0f, 16, width, height);
    const float px = diagonal.back().x * width, py = diagonal.back().y * height;
    EXPECT_NEAR(std::hypot(px, py), 0.5f, 1e-6f);
    EXPECT_NEAR(std::atan2(-py, px) * 180.0f / 3.14159265f, 120.0f, 1e-3f) << "counter-clockwise on screen";
    for (std::size_t i = 0; i < diagonal.size(); ++i) {
        EXPECT_NEAR(diagonal[i].x, -diagonal[diagonal.size() - 1 - i].x, 1e-7f);
        EXPECT_NEAR(diagonal[i].y, -diagonal[diagonal.size() - 1 - i].y, 1e-7f);
    }
}

} // namespace
} // namespace defocus
