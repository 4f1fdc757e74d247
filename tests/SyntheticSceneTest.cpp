// SPDX-License-Identifier: LGPL-2.1-or-later
// The synthetic scenes' sampling and settings, without GL: lens positions fill the aperture
// polygon uniformly by area with the documented orientation, pixel offsets fill the pixel.
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "sources/SyntheticScene.hpp"

namespace defocus {
namespace {

constexpr double kPi = std::numbers::pi;

/// True when `p` is inside the regular polygon of circumradius 1 with a corner at `cornerDeg`.
bool insidePolygon(glm::dvec2 p, int blades, double cornerDeg)
{
    // Inside iff the projection on every edge normal is at most the apothem cos(pi / n).
    for (int k = 0; k < blades; ++k) {
        const double normal = (cornerDeg + 180.0 / blades + 360.0 * k / blades) * kPi / 180.0;
        if (p.x * std::cos(normal) + p.y * std::sin(normal) > std::cos(kPi / blades) + 1e-9)
            return false;
    }
    return true;
}

TEST(SyntheticSampling, LensPositionsFillTheApertureUniformly)
{
    for (const int blades : {5, 6, 9}) {
        const auto points = apertureSamples(blades, 0.0, 256);
        ASSERT_EQ(points.size(), 256u);
        glm::dvec2 mean(0.0);
        double secondMoment = 0.0;
        for (const auto& p : points) {
            EXPECT_TRUE(insidePolygon(p, blades, 90.0)) << p.x << ", " << p.y;
            mean += p / 256.0;
            secondMoment += glm::dot(p, p) / 256.0;
        }
        // Centred: a stratified set's mean is off by far less than one point's share (1/256).
        EXPECT_NEAR(mean.x, 0.0, 0.01);
        EXPECT_NEAR(mean.y, 0.0, 0.01);
        // Uniform by area: E|p|^2 over a regular n-gon of circumradius 1 is
        // (1 + 2 cos^2(pi/n)) / 6 (its polar moment over its area); a ring-biased or
        // centre-biased set misses it by far more than 1%.
        const double c = std::cos(kPi / blades);
        EXPECT_NEAR(secondMoment, (1.0 + 2.0 * c * c) / 6.0, 0.01) << blades << " blades";
    }
}

TEST(SyntheticSampling, RotationZeroPutsACornerStraightUp)
{
    // The farthest lens position from the centre lies near a corner: up for rotation 0, and
    // 30 degrees counter-clockwise (towards -x) of it for rotation 30.
    for (const double rotation : {0.0, 30.0}) {
        glm::dvec2 farthest(0.0);
        for (const auto& p : apertureSamples(6, rotation, 4096))
            if (glm::dot(p, p) > glm::dot(farthest, farthest))
                farthest = p;
        const double angle = std::atan2(farthest.y, farthest.x) * 180.0 / kPi;
        const double offset = std::remainder(angle - (90.0 + rotation), 60.0);
        EXPECT_LT(std::abs(offset), 3.0) << "rotation " << rotation << ": farthest point at " << angle;
        EXPECT_GT(glm::length(farthest), 0.97);
    }
}

TEST(SyntheticSampling, PixelOffsetsCoverThePixel)
{
    const auto offsets = pixelJitter(16);
    ASSERT_EQ(offsets.size(), 16u);
    int cells[4][4] = {};
    for (const auto& o : offsets) {
        ASSERT_GE(o.x, -0.5);
        ASSERT_LT(o.x, 0.5);
        ASSERT_GE(o.y, -0.5);
        ASSERT_LT(o.y, 0.5);
        ++cells[static_cast<int>((o.y + 0.5) * 4)][static_cast<int>((o.x + 0.5) * 4)];
    }
    // 16 Hammersley points: one in each cell of the 4 x 4 grid.
    for (const auto& row : cells)
        for (const int n : row)
            EXPECT_EQ(n, 1);
    EXPECT_EQ(pixelJitter(1).front(), glm::dvec2(0.0)); // one sample: the pixel centre
}

TEST(SyntheticSettingsCheck, ValidateNamesEachBadField)
{
    EXPECT_TRUE(validate(SyntheticSettings{}).empty());
    SyntheticSettings s;
    s.width = 8;
    s.aperture.blades = 2;
    s.aperture.samples = 0;
    s.lens.fNumber = 0.1;
    s.lens.bladeRotationDeg = 400.0;
    EXPECT_EQ(validate(s).size(), 5u);
}

TEST(SyntheticSettingsCheck, NamedScenesAndUnknownNames)
{
    for (const auto& name : syntheticSceneNames()) {
        const SceneDescription scene = syntheticScene(name);
        EXPECT_EQ(scene.name, name);
        EXPECT_GT(scene.objects.size(), 10u);
        EXPECT_NE(scene.focusFromM, scene.focusToM) << "every named shot pulls focus";
    }
    EXPECT_THROW(syntheticScene("nope"), std::invalid_argument);
}

} // namespace
} // namespace defocus
