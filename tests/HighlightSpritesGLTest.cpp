// SPDX-License-Identifier: LGPL-2.1-or-later
// Bokeh sprites (HighlightSpritePass, highlight_sprites.comp, highlight_sprite.vert/.frag): the
// light of blurred pixels above white scattered in the aperture's shape (any blade count, the circle,
// squeezed) with exact edges, only on frames with such lights.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "bench/methods/ReferenceScatter.hpp"
#include "filter/Aperture.hpp"
#include "filter/Pipeline.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

class HighlightSprites : public test::GLTest {
protected:
    static QualitySettings quality(bool sprites)
    {
        QualitySettings q;
        q.samples = 12;
        q.targetFormat = TargetFormat::Rgba32F;
        q.highlightSprites = sprites;
        return q;
    }
    /// A dark frame with one light of `energy` at `at`, everything 2 m away (CoC `coc` px).
    static cv::Mat light(cv::Point at, float energy, cv::Size size = {96, 96})
    {
        cv::Mat color(size, CV_32FC3, cv::Scalar::all(0.0));
        color.at<cv::Vec3f>(at) = cv::Vec3f::all(energy);
        return color;
    }
};

TEST_F(HighlightSprites, ALightBecomesAHexagonWithExactEdgesAndAllItsEnergy)
{
    const double diameter = 30.0;
    const cv::Mat color = light({48, 48}, 1000.0f);
    const cv::Mat far(color.size(), CV_32F, cv::Scalar(2.0f));
    Pipeline pipeline;
    const cv::Mat out = pipeline.run({color, far, 0.0, 0, "light"}, test::lensWithFarCoc(diameter), quality(true),
                                     View::Composite, Encoding::Linear32F);
    EXPECT_TRUE(pipeline.plan().highlightSprites);
    cv::Mat gray;
    cv::cvtColor(out, gray, cv::COLOR_BGR2GRAY);
    // All of the light, in the frame: float sums over ~600 pixels, 0.5 %.
    EXPECT_NEAR(cv::sum(gray)[0], 1000.0, 5.0);

    // The exact hexagon, a corner on top, circumradius 15 px, centred on the light's pixel: the
    // area it covers of each pixel (the CPU reference's polygonSquareOverlap). The sprite's edge
    // ramp is one pixel wide, like an area-sampled edge.
    const double radius = diameter / 2.0;
    const ScatterOptions corners; // rotation 0: a corner on top, as the lens's
    cv::Mat exact(gray.size(), CV_64F, cv::Scalar(0.0));
    for (int y = 0; y < gray.rows; ++y)
        for (int x = 0; x < gray.cols; ++x)
            exact.at<double>(y, x) = polygonSquareOverlap(corners, 48.5, 48.5, radius, x, y);
    exact *= 1000.0 / cv::sum(exact)[0];
    cv::Mat difference, gray64;
    gray.convertTo(gray64, CV_64F);
    cv::absdiff(gray64, exact, difference);
    double worst = 0.0;
    cv::minMaxLoc(difference, nullptr, &worst);
    const double plateau = 1000.0 / (3.0 * std::sqrt(3.0) / 2.0 * radius * radius);
    // Measured against the exact hexagon: worst pixel 0.15 of the plateau (at the corners, where
    // the ramp on the distance to the nearest edge misjudges the covered area), RMS 0.003; the
    // rhombi alone, without sprites: worst 0.71 (bilinear taps smear the third rhombus' edges),
    // RMS 0.042.
    const double rms = std::sqrt(cv::mean(difference.mul(difference))[0]) / plateau;
    std::printf("[ FIGURE   ] sprites: worst %.3f, rms %.4f of the plateau\n", worst / plateau, rms);
    EXPECT_LT(worst / plateau, 0.2);
    const cv::Mat without = pipeline.run({color, far, 0.0, 0, "light"}, test::lensWithFarCoc(diameter),
                                         quality(false), View::Composite, Encoding::Linear32F);
    cv::cvtColor(without, gray, cv::COLOR_BGR2GRAY);
    gray.convertTo(gray64, CV_64F);
    cv::absdiff(gray64, exact, difference);
    double worstWithout = 0.0;
    cv::minMaxLoc(difference, nullptr, &worstWithout);
    const double rmsWithout = std::sqrt(cv::mean(difference.mul(difference))[0]) / plateau;
    std::printf("[ FIGURE   ] gather alone: worst %.3f, rms %.4f of the plateau\n", worstWithout / plateau,
                rmsWithout);
    EXPECT_LT(rms, 0.5 * rmsWithout) << "the sprites' edges are sharper than the gather's";
}

/// The share of each pixel of a `size` frame that the aperture `lens` (blades, rotation, ratio) of
/// circumradius `radius` centred at `centre` covers, behind the focus: drawn 16 times as large
/// with OpenCV from its corners (at the rotation + pi / n + 2 pi k / n, counter-clockwise, y up,
/// as Cycles' regular_polygon_sample() places them; x divided by the ratio) or as an ellipse, and
/// averaged down. Independent of filter/Aperture.cpp, which works from the edges' normals.
cv::Mat supersampledAperture(const LensSettings& lens, cv::Size size, cv::Point2d centre, double radius)
{
    constexpr int kScale = 16, kShift = 4; // fillPoly's fixed point: 4 fractional bits
    cv::Mat big(size * kScale, CV_8U, cv::Scalar(0));
    const auto fixed = [](double v) { return static_cast<int>(std::lround(v * kScale * (1 << kShift))); };
    // Pixel (x, y) spans [x, x + 1) x [y, y + 1); the big image's sample (X, Y) sits at (X + 0.5) / 16.
    const double cx = centre.x * kScale - 0.5, cy = centre.y * kScale - 0.5;
    const double rx = radius * kScale / lens.apertureRatio, ry = radius * kScale;
    if (lens.blades == 0) {
        cv::ellipse(big, cv::Point(fixed(cx / kScale), fixed(cy / kScale)),
                    cv::Size(fixed(rx / kScale), fixed(ry / kScale)), 0.0, 0.0, 360.0, cv::Scalar(255), cv::FILLED,
                    cv::LINE_8, kShift);
    } else {
        std::vector<cv::Point> corners;
        for (int k = 0; k < lens.blades; ++k) {
            const double angle = lens.bladeRotationDeg * std::numbers::pi / 180.0 + std::numbers::pi / lens.blades +
                                 2.0 * std::numbers::pi * k / lens.blades;
            corners.emplace_back(fixed((cx + rx * std::cos(angle)) / kScale), fixed((cy - ry * std::sin(angle)) / kScale));
        }
        cv::fillPoly(big, std::vector<std::vector<cv::Point>>{corners}, cv::Scalar(255), cv::LINE_8, kShift);
    }
    cv::Mat coverage;
    big.convertTo(big, CV_64F, 1.0 / 255.0);
    cv::resize(big, coverage, size, 0, 0, cv::INTER_AREA);
    return coverage;
}

struct ApertureCase {
    const char* name;
    int blades;
    double rotationDeg, ratio;
};
void PrintTo(const ApertureCase& c, std::ostream* os)
{
    *os << c.name;
}

class ApertureSprites : public HighlightSprites, public ::testing::WithParamInterface<ApertureCase> {};

// Defect caught: a light drawn in the wrong shape (the hexagon whatever the blades, a polygon
// turned or squeezed the wrong way, the circle's radius off by the gather's scale), or its energy
// lost or doubled (an area that is not the shape's, or sprites and gather both keeping it).
TEST_P(ApertureSprites, ALightBecomesTheApertureWithExactEdgesAndAllItsEnergy)
{
    const ApertureCase& c = GetParam();
    const double diameter = 30.0;
    const cv::Mat color = light({48, 48}, 1000.0f);
    const cv::Mat far(color.size(), CV_32F, cv::Scalar(2.0f));
    LensSettings lens = test::lensWithFarCoc(diameter);
    lens.blades = c.blades;
    lens.bladeRotationDeg = c.rotationDeg;
    lens.apertureRatio = c.ratio;
    Pipeline pipeline;
    const cv::Mat out = pipeline.run({color, far, 0.0, 0, "light"}, lens, quality(true), View::Composite,
                                     Encoding::Linear32F);
    EXPECT_TRUE(pipeline.plan().highlightSprites);
    cv::Mat gray, gray64;
    cv::cvtColor(out, gray, cv::COLOR_BGR2GRAY);
    gray.convertTo(gray64, CV_64F);
    EXPECT_NEAR(cv::sum(gray)[0], 1000.0, 5.0); // float sums over ~700 pixels, 0.5 %

    cv::Mat exact = supersampledAperture(lens, gray.size(), {48.5, 48.5}, diameter / 2.0);
    const double area = cv::sum(exact)[0];
    // The shape's area from its own formula: what the gather's scale and the sprites divide by.
    EXPECT_NEAR(area, apertureArea(ApertureShape::of(lens)) * diameter * diameter / 4.0, 0.01 * area);
    exact *= 1000.0 / area;
    const double plateau = 1000.0 / area;
    cv::Mat difference;
    cv::absdiff(gray64, exact, difference);
    double worst = 0.0;
    cv::minMaxLoc(difference, nullptr, &worst);
    const double rms = std::sqrt(cv::mean(difference.mul(difference))[0]) / plateau;
    std::printf("[ FIGURE   ] %s: worst %.3f, rms %.4f of the plateau\n", c.name, worst / plateau, rms);
    // The sprite's ramp on the distance to the nearest edge covers half of a pixel centred on a
    // corner, where a corner of angle theta covers theta / 2 pi of it: 0.5 - theta / 2 pi worst
    // (0.33 for the triangle, 0.17 for the hexagon, 0 for the circle); the reference's 1/16 px
    // raster moves its edges by up to 1/16 of a pixel's coverage; 0.01 for float sums. A shape
    // turned by half a blade, or scaled by the gather's factor, puts whole pixels of plateau
    // wrong (worst ~1). RMS: a quarter of the gather's alone on the hexagon (0.042, above).
    const double corner = c.blades == 0 ? 0.0 : 0.5 - (c.blades - 2.0) / (2.0 * c.blades);
    EXPECT_LT(worst / plateau, corner + 1.0 / 16.0 + 0.01);
    EXPECT_LT(rms, 0.042 / 4.0);
}

INSTANTIATE_TEST_SUITE_P(EveryShape, ApertureSprites,
                         ::testing::Values(ApertureCase{"hexagon", 6, 0.0, 1.0}, ApertureCase{"circle", 0, 0.0, 1.0},
                                           ApertureCase{"triangle", 3, 0.0, 1.0}, ApertureCase{"pentagon", 5, 0.0, 1.0},
                                           ApertureCase{"heptagon_turned_15", 7, 15.0, 1.0},
                                           ApertureCase{"octagon", 8, 0.0, 1.0}, ApertureCase{"nonagon", 9, 0.0, 1.0},
                                           ApertureCase{"sixteen", 16, 0.0, 1.0},
                                           ApertureCase{"oval_tall", 0, 0.0, 2.0},
                                           ApertureCase{"pentagon_wide", 5, 10.0, 0.6}),
                         [](const ::testing::TestParamInfo<ApertureCase>& p) { return p.param.name; });

TEST_F(HighlightSprites, ALightFillingAThirdOfItsNeighbourhoodMakesSprites)
{
    // Catches a large light left to the gather: a light judged a bright surface because it
    // fills more than a quarter of the 3x3 tiles around its pixels (the lights at 1.6-3 m of the
    // corpus' spheres scenes, 30 % of theirs, lost their sharp, bright bokeh rims: spheres-far-
    // focus 32.85 against 38.74 dB balanced). A 28 x 28 light of 40 (34 % of the 48 x 48 px
    // around its middle) at 1.5 m (10 px of CoC) before a dark background at 2 m (20 px), where
    // the gather brings only white's worth of the nearer, sharper light (the bleeding rule); the
    // frame large enough for the budget of sprites (one per 64 pixels) to hold the light's.
    cv::Mat color(256, 256, CV_32FC3, cv::Scalar::all(0.02));
    cv::Mat far(color.size(), CV_32F, cv::Scalar(2.0f));
    const cv::Rect square(114, 114, 28, 28);
    color(square).setTo(cv::Scalar::all(40.0));
    far(square).setTo(1.5f);
    Pipeline pipeline;
    const cv::Mat with = pipeline.run({color, far, 0.0, 0, "large light"}, test::lensWithFarCoc(20.0), quality(true),
                                      View::Composite, Encoding::Linear32F);
    const cv::Mat without = pipeline.run({color, far, 0.0, 0, "large light"}, test::lensWithFarCoc(20.0),
                                         quality(false), View::Composite, Encoding::Linear32F);
    // The sprites carry the light above white to the rim of its bokeh, where the gather alone
    // brings white's worth: the outputs differ there by a tenth of the light's level or more (0
    // where no pixel made a sprite), and the light stays whole (float sums over 65536 pixels).
    double largest = 0.0;
    const cv::Mat change = cv::abs(with - without);
    cv::minMaxLoc(change.reshape(1), nullptr, &largest);
    std::printf("[ FIGURE   ] large light: sprites change a pixel by up to %.2f of the light's level\n", largest / 40.0);
    EXPECT_GT(largest, 4.0);
    EXPECT_NEAR(cv::sum(with)[0] / cv::sum(color)[0], 1.0, 0.01);
}

TEST_F(HighlightSprites, ALightAtTheEdgeKeepsItsEnergyInTheFrame)
{
    // 2 px from the left edge, a 30 px hexagon: most of it would fall outside; the sprite's
    // mirror image brings it back, as lights beyond the frame would bring theirs.
    const cv::Mat color = light({2, 48}, 1000.0f);
    const cv::Mat far(color.size(), CV_32F, cv::Scalar(2.0f));
    Pipeline pipeline;
    const cv::Mat out = pipeline.run({color, far, 0.0, 0, "edge light"}, test::lensWithFarCoc(30.0), quality(true),
                                     View::Composite, Encoding::Linear32F);
    cv::Mat gray;
    cv::cvtColor(out, gray, cv::COLOR_BGR2GRAY);
    EXPECT_NEAR(cv::sum(gray)[0], 1000.0, 10.0);
}

TEST_F(HighlightSprites, RunOnlyWhereThereAreLightsThatStandOut)
{
    const cv::Mat far(96, 96, CV_32F, cv::Scalar(2.0f));
    const LensSettings lens = test::lensWithFarCoc(20.0);
    Pipeline pipeline;
    // Nothing above white: no sprites.
    pipeline.run({light({48, 48}, 0.9f), far, 0.0, 0, "dim"}, lens, quality(true), View::Composite,
                 Encoding::Linear32F);
    EXPECT_FALSE(pipeline.plan().highlightSprites);
    // A bright region, 40 % of the frame far above white: the plan runs the pass, but no pixel
    // stands out of a tile that is not mostly bright, so the gather spreads it all, to the bit
    // as without sprites.
    cv::Mat region(96, 96, CV_32FC3, cv::Scalar::all(0.2));
    region.colRange(0, 38).setTo(cv::Scalar::all(50.0));
    const auto same = [&](const cv::Mat& color, const char* name) {
        const cv::Mat with = pipeline.run({color, far, 0.0, 0, name}, lens, quality(true), View::Composite,
                                          Encoding::Linear32F);
        EXPECT_TRUE(pipeline.plan().highlightSprites) << name;
        const cv::Mat without = pipeline.run({color, far, 0.0, 0, name}, lens, quality(false), View::Composite,
                                             Encoding::Linear32F);
        EXPECT_EQ(cv::norm(with, without, cv::NORM_INF), 0.0) << name;
    };
    same(region, "bright region");
    // Lights every 4 px: 576 sprites, over the frame's budget of 9216 / 64 = 144: none is drawn
    // and the gather keeps their light, to the bit as without sprites.
    cv::Mat lights(96, 96, CV_32FC3, cv::Scalar::all(0.1));
    for (int y = 2; y < 96; y += 4)
        for (int x = 2; x < 96; x += 4)
            lights.at<cv::Vec3f>(y, x) = cv::Vec3f::all(100.0f);
    same(lights, "many lights");
    // 8-bit video: clipped lights are white at most, unless the highlight gain scales them up.
    cv::Mat video(96, 96, CV_8UC3, cv::Scalar::all(40));
    video(cv::Rect(46, 46, 3, 3)).setTo(cv::Scalar::all(255));
    pipeline.run({video, far, 0.0, 0, "video"}, lens, quality(true), View::Composite, Encoding::Linear32F);
    EXPECT_FALSE(pipeline.plan().highlightSprites);
    QualitySettings gained = quality(true);
    gained.highlightGain = 8.0;
    pipeline.run({video, far, 0.0, 0, "video"}, lens, gained, View::Composite, Encoding::Linear32F);
    EXPECT_TRUE(pipeline.plan().highlightSprites);
}

// A light in or just in front of the focus over a blurred background: only the light's own small
// blur may spread its light. The defect: a blurred pixel's gather took a nearer, sharper light
// that does not reach it (the rhombi's bleeding rule lets such a tap in by its blurriness, and
// fully below the rule's bias) with all of its HDR brightness, so every background pixel within
// reach of the light drew it a second time, a pale hexagon as large as the background's blur
// (docs/accuracy.md, the ghost hexagon of the corpus scene overlapping-lights). Three lights: in
// focus (|CoC| < 1 px, no sprite), a little blurred (a sprite takes its light above white), and
// one whose antialiased edge pixels carry the background's depth, as a renderer's depth pass,
// not antialiased, gives them (the edge's light then took the background's blur).
TEST_F(HighlightSprites, ALightInFrontOfABlurredBackgroundIsNotDrawnASecondTimeByTheBlurBehindIt)
{
    struct Case {
        const char* name;
        float depthM;  // the light's: FocalRange, focus 1 m, -30 px at 0.5 m
        bool edge;     // a ring of edge pixels, a third of the light, at the background's depth
    };
    const cv::Size size{128, 96};
    const cv::Rect square{62, 46, 5, 5};
    const float background = 0.02f, level = 50.0f;
    // Outside the light's own reach (its 1.8 px blur, the half size's upscale): 3 px around.
    cv::Mat outside(size, CV_8U, cv::Scalar(255));
    outside(cv::Rect(square.x - 4, square.y - 4, square.width + 8, square.height + 8)).setTo(0);
    for (const Case& c : {Case{"in focus", 0.99f, false}, Case{"1.8 px", 0.97f, false},
                          Case{"antialiased edge", 0.97f, true}}) {
        cv::Mat color(size, CV_32FC3, cv::Scalar::all(background));
        cv::Mat depth(size, CV_32F, cv::Scalar(2.0f)); // +30 px of CoC
        color(square).setTo(cv::Scalar::all(level));
        depth(square).setTo(c.depthM);
        double energy = level * static_cast<double>(square.area());
        if (c.edge) {
            const cv::Rect ring{square.x - 1, square.y - 1, square.width + 2, square.height + 2};
            for (int y = ring.y; y < ring.br().y; ++y)
                for (int x = ring.x; x < ring.br().x; ++x)
                    if (!square.contains({x, y})) {
                        color.at<cv::Vec3f>(y, x) = cv::Vec3f::all(level / 3.0f);
                        energy += level / 3.0f;
                    }
        }
        for (const test::NamedQuality& preset : test::shippedPresets()) {
            Pipeline pipeline;
            const cv::Mat out = pipeline.run({color, depth, 0.0, 0, c.name}, test::lensWithFarCoc(30.0),
                                             preset.quality, View::Composite, Encoding::Linear32F);
            cv::Mat gray;
            cv::cvtColor(out, gray, cv::COLOR_BGR2GRAY);
            // The blur of a flat background is the background: what lies above it outside the
            // light's reach is light drawn where the lens puts none.
            cv::Mat excess = gray - background;
            excess.setTo(0.0, excess < 0.0);
            excess.setTo(0.0, outside == 0);
            const double stray = cv::sum(excess)[0] / energy;
            std::printf("[ FIGURE   ] %s, %s: %.3f of the light outside its reach\n", c.name, preset.name.c_str(),
                        stray);
            // The second hexagon held 52-70 % of the light in focus and 18 % with the edge at the
            // background's depth. The gather keeps white's worth of a light that makes sprites;
            // while the rule hid only taps above white, that white's worth still lit the
            // background as far as its blur reached: 1.5-2.6 % of the light outside its reach
            // for the blurred light and its antialiased edge. Hidden, 0.1-0.3 % is left: the
            // bilinear taps at the light's edge mix a share of it with the background's CoC.
            EXPECT_LT(stray, 0.008) << c.name << ", " << preset.name;
            // In focus: a tap above white that its own blur does not bring here is hidden, not
            // lit (counted as white's worth instead, it left 7.4-7.6 % of the light outside its
            // reach, 3.3 % at full size), and the light enters the blur as what lies round it
            // (coc.frag, standIn()): 0.000 at every preset, against 3.9-4.3 % at half size with
            // all of the light and 1.0-1.4 % with white's worth of it (1.6 % and 1.0 % at full
            // size). The light's own pixels keep their brightness: InFocusLightPass puts them
            // back.
            if (c.depthM == 0.99f) {
                EXPECT_LT(stray, 0.005) << c.name << ", " << preset.name;
                const double kept = cv::mean(gray(square))[0] / level;
                std::printf("[ FIGURE   ] %s, %s: the light's own pixels at %.4f of their level\n", c.name,
                            preset.name.c_str(), kept);
                EXPECT_NEAR(kept, 1.0, 0.02) << c.name << ", " << preset.name;
            }
        }
    }
}

// A light in focus that a blurred foreground partly covers shows the share of it that the
// foreground leaves. With bokeh sprites the CoC pass lets such a light into the blur at white's
// worth only (coc.frag) and the rest is put back afterwards; what comes back must be weighed by
// the foreground's coverage as the blur itself weighs the pixel. The share is measured as the
// output's slope in the light's level, between two levels above white (the blur then sees the
// same capped light both times, so everything but the share cancels), against the same slope
// without sprites, where the blur treats the light as any colour. Defects: the light put back in
// full under the foreground (slope 1), not put back (slope 0), or weighed along other lines or
// taps than the blur's.
TEST_F(HighlightSprites, ALightInFocusUnderABlurredForegroundShowsTheShareTheForegroundLeaves)
{
    const cv::Size size{96, 64};
    const cv::Rect light{42, 30, 2, 2};
    const auto frame = [&](float level) {
        cv::Mat color(size, CV_32FC3, cv::Scalar::all(0.05));
        color(light).setTo(cv::Scalar::all(level));
        return color;
    };
    // FocalRange, focus 1 m: the light and the background round it in focus, in a window of a
    // foreground at 0.7 m, -18 px of CoC, whose blur reaches 9 px: over the light from every
    // side, so that every line of the blur crosses it.
    cv::Mat depth(size, CV_32F, cv::Scalar(0.7f));
    depth(cv::Rect(light.x - 4, light.y - 4, 10, 10)).setTo(1.0f);
    const LensSettings lens = test::lensWithFarCoc(30.0);
    for (const float rotation : {0.0f, 15.0f}) {
        LensSettings turned = lens;
        turned.bladeRotationDeg = rotation;
        for (const test::NamedQuality& preset : test::shippedPresets()) {
            const auto slope = [&](bool sprites) {
                QualitySettings quality = preset.quality;
                quality.highlightSprites = sprites;
                Pipeline pipeline;
                cv::Mat low = pipeline.run({frame(20.0f), depth, 0.0, 0, "low"}, turned, quality, View::Composite,
                                           Encoding::Linear32F);
                EXPECT_EQ(pipeline.plan().highlightSprites, sprites);
                cv::Mat high = pipeline.run({frame(60.0f), depth, 0.0, 0, "high"}, turned, quality, View::Composite,
                                            Encoding::Linear32F);
                cv::Mat slopes;
                cv::extractChannel((high - low) / 40.0f, slopes, 1);
                return slopes(light).clone();
            };
            const cv::Mat with = slope(true), without = slope(false);
            const bool half = preset.quality.resolution == Resolution::Half;
            for (int y = 0; y < light.height; ++y)
                for (int x = 0; x < light.width; ++x) {
                    const double share = with.at<float>(y, x), plain = without.at<float>(y, x);
                    std::printf("[ FIGURE   ] %s, rotation %.0f, pixel (%d, %d): share %.4f, without sprites %.4f\n",
                                preset.name.c_str(), rotation, x, y, share, plain);
                    // At full size the blur weighs the pixel alike with and without sprites: the
                    // slopes agree (to 4 decimals here; the light's share in the foreground's own
                    // blur, which only the plain path has, is that small). At half size the light
                    // fills one texel, which the upscale's bil(R - C) carries by 9/16 at each of
                    // its pixels: the plain slope is 1 - 9/16 a for the texel's coverage a, and
                    // the light comes back by the texel's share, 1 - a.
                    const double expected = half ? 1.0 - (16.0 / 9.0) * (1.0 - plain) : plain;
                    EXPECT_NEAR(share, expected, 0.005) << preset.name << ", rotation " << rotation;
                    // The case is one: the foreground covers a fair part of the light, not all.
                    EXPECT_GT(share, 0.3) << preset.name;
                    EXPECT_LT(share, 0.9) << preset.name;
                }
        }
    }
}

} // namespace
} // namespace defocus
