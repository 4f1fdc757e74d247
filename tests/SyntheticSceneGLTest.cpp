// SPDX-License-Identifier: LGPL-2.1-or-later
// The synthetic ground truth checked against the lens model it claims to follow: a point light's
// bokeh has the filter's thin-lens CoC and the documented orientation, a tiny aperture gives the
// pinhole image, light is conserved, depth is planar; and the Cycles truth agrees on both.
// Small images and sample counts keep the file at a few seconds on llvmpipe (each sample is one
// full render); every tolerance says what it allows for.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/methods/Method.hpp"
#include "filter/Lens.hpp"
#include "sources/ImageIO.hpp"
#include "sources/SyntheticSource.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

constexpr double kPi = std::numbers::pi;

class SyntheticSceneGL : public test::GLTest {};

/// One emissive sphere on the view axis at `depthM`, in front of a black wall at 60 m, the
/// camera at the origin looking down -z.
SceneDescription pointScene(double depthM, double radiusM)
{
    SceneDescription scene;
    scene.name = "point";
    SceneObject wall;
    wall.centre = {0.0f, 0.0f, -61.0f};
    wall.halfSize = {200.0f, 200.0f, 1.0f};
    wall.material.colorA = glm::vec3(0.0f);
    scene.objects.push_back(wall);
    SceneObject light;
    light.shape = SceneObject::Shape::Sphere;
    light.centre = {0.0f, 0.0f, static_cast<float>(-depthM)};
    light.halfSize = glm::vec3(static_cast<float>(radiusM));
    light.material.colorA = glm::vec3(1.0f);
    light.material.emission = 50.0f;
    scene.objects.push_back(light);
    scene.from = scene.to = {{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}};
    return scene;
}

/// 100 mm f/1.4 focused at 1 m on a 36 mm sensor: at 160 px a point at 3 m blurs to 23.5 px,
/// large enough to measure a shape in a 160 px wide image.
SyntheticSettings pointSettings(int width, int height, int samples)
{
    SyntheticSettings s;
    s.width = width;
    s.height = height;
    s.frames = 1;
    s.lens.focalLengthMm = 100.0;
    s.lens.fNumber = 1.4;
    s.lens.focusM = 1.0;
    s.lens.sensorWidthMm = 36.0;
    s.focusPull = false;
    s.aperture.samples = samples;
    s.pinholeSamples = 16;
    return s;
}

/// The radius of a sphere whose pinhole image is `pixels` wide at `depthM` (thin lens: the
/// image distance v sets the scale, v W / sensor pixels per unit of tangent).
double radiusForPixels(const SyntheticSettings& s, double depthM, double pixels)
{
    const double f = s.lens.focalLengthMm * 1e-3;
    const double v = f * s.lens.focusM / (s.lens.focusM - f);
    const double pixelsPerTangent = v * s.width / (s.lens.sensorWidthMm * 1e-3);
    return 0.5 * pixels * depthM / pixelsPerTangent;
}

cv::Mat luminance(const cv::Mat& bgr)
{
    cv::Mat grey;
    cv::transform(bgr, grey, cv::Matx13f(1.0f / 3, 1.0f / 3, 1.0f / 3));
    return grey;
}

/// What a bokeh measures like, from the light's pixels within `radius` of `centre`.
struct Bokeh {
    double energy = 0.0;       ///< sum of (value - background) in the window
    double plateau = 0.0;      ///< mean over the inner disc: the level of the flat top
    double areaDiameter = 0.0; ///< circumscribed diameter of the regular polygon of area energy / plateau
    double rowWidth = 0.0;     ///< energy of the rows through the centroid (+-2) over the plateau, per row
    double cornerDeg = 0.0;    ///< direction of a corner, degrees CCW from +x with y up, mod 360 / blades
    int topWidth = 0;          ///< lit pixels (> half plateau) in the second row from the top of the mask
    int bottomWidth = 0;       ///< and from its bottom
    cv::Point2d centroid;
};

/// Measures the bokeh of one light, of expected diameter `diameter`. A bokeh is the aperture
/// polygon convolved with the light's own image: energy over plateau is the polygon's area
/// however soft its edges are, and so is a row's energy over the plateau its width, where the
/// polygon's sides are vertical (corner up) over the light's height. The corner direction is the
/// phase of the blades-fold angular moment of the half-plateau mask (whose radius peaks at the
/// corners). The plateau is a mean, not a median: the accumulated bokeh is a sum of discrete
/// copies of the light, so its values come in steps.
Bokeh measureBokeh(const cv::Mat& bgr, cv::Point2d centre, double diameter, int blades, bool subtractBackground)
{
    const cv::Mat grey = luminance(bgr);
    const double radius = 0.5 * diameter + 3.0;
    const auto inWindow = [&](int x, int y) { return std::hypot(x - centre.x, y - centre.y) <= radius; };
    Bokeh b;
    double background = 0.0;
    if (subtractBackground) {
        std::vector<float> ring;
        for (int y = 0; y < grey.rows; ++y)
            for (int x = 0; x < grey.cols; ++x) {
                const double r = std::hypot(x - centre.x, y - centre.y);
                if (r > radius && r < radius + 4.0)
                    ring.push_back(grey.at<float>(y, x));
            }
        std::nth_element(ring.begin(), ring.begin() + static_cast<long>(ring.size() / 2), ring.end());
        background = ring[ring.size() / 2];
    }
    const auto value = [&](int x, int y) { return grey.at<float>(y, x) - background; };
    double sx = 0.0, sy = 0.0;
    for (int y = 0; y < grey.rows; ++y)
        for (int x = 0; x < grey.cols; ++x)
            if (inWindow(x, y)) {
                b.energy += value(x, y);
                sx += value(x, y) * x;
                sy += value(x, y) * y;
            }
    b.centroid = {sx / b.energy, sy / b.energy};
    // Plateau: within a quarter of the diameter of the centre, inside the inscribed circle
    // (0.43 d for a hexagon) by more than the radius of the lights used here.
    double inner = 0.0;
    int innerCount = 0;
    for (int y = 0; y < grey.rows; ++y)
        for (int x = 0; x < grey.cols; ++x)
            if (std::hypot(x - b.centroid.x, y - b.centroid.y) <= 0.25 * diameter) {
                inner += value(x, y);
                ++innerCount;
            }
    b.plateau = inner / innerCount;
    const double area = b.energy / b.plateau;
    // A regular n-gon of circumradius R has area n/2 R^2 sin(2 pi / n).
    b.areaDiameter = 2.0 * std::sqrt(2.0 * area / (blades * std::sin(2.0 * kPi / blades)));

    const int centreRow = static_cast<int>(std::lround(b.centroid.y));
    double rows = 0.0;
    for (int y = centreRow - 2; y <= centreRow + 2; ++y)
        for (int x = 0; x < grey.cols; ++x)
            if (inWindow(x, y))
                rows += value(x, y);
    b.rowWidth = rows / 5.0 / b.plateau;

    const double half = 0.5 * b.plateau;
    std::complex<double> moment = 0.0;
    int top = grey.rows, bottom = -1;
    for (int y = 0; y < grey.rows; ++y)
        for (int x = 0; x < grey.cols; ++x)
            if (inWindow(x, y) && value(x, y) > half) {
                const std::complex<double> p(x - b.centroid.x, -(y - b.centroid.y)); // y up
                moment += std::pow(p, blades);
                top = std::min(top, y);
                bottom = std::max(bottom, y);
            }
    const double period = 360.0 / blades;
    b.cornerDeg = std::fmod(std::arg(moment) * 180.0 / kPi / blades + 2.0 * period, period);
    const auto litInRow = [&](int y) {
        int count = 0;
        for (int x = 0; x < grey.cols; ++x)
            count += inWindow(x, y) && value(x, y) > half;
        return count;
    };
    b.topWidth = litInRow(top + 1);
    b.bottomWidth = litInRow(bottom - 1);
    return b;
}

/// Smallest difference between two angles modulo `period`, degrees.
double angleDistance(double a, double b, double period)
{
    const double d = std::fmod(std::abs(a - b), period);
    return std::min(d, period - d);
}

TEST_F(SyntheticSceneGL, PointLightBokehHasTheFiltersCocDiameter)
{
    // The light is 6 px wide through the pinhole: 256 lens positions then stack about 17 copies
    // of it on each pixel of its 23.5 px bokeh, enough for a level plateau (a 2 px light gets
    // 2 copies per pixel, which is mostly noise).
    for (const double depth : {3.0, 0.7}) { // behind the focus (1 m) and in front of it
        SyntheticSettings s = pointSettings(160, 120, 256);
        SyntheticScene scene(pointScene(depth, radiusForPixels(s, depth, 6.0)), s);
        const SyntheticImages images = scene.render(0);
        ASSERT_EQ(images.reference.type(), CV_32FC3);
        ASSERT_EQ(images.reference.size(), cv::Size(160, 120));
        const double coc = std::abs(thinLensCocPixels(s.lens, s.width, depth));
        const Bokeh b = measureBokeh(images.reference, {79.5, 59.5}, coc, 6, false);
        // Corner up: the horizontal width across the flat sides is d cos 30.
        const double fromWidth = b.rowWidth / std::cos(kPi / 6.0);
        std::printf("[ FIGURE   ] point at %.1f m: thin-lens CoC %.2f px; reference: %.2f px from its area, %.2f px "
                    "from its width\n",
                    depth, coc, b.areaDiameter, fromWidth);
        // 1 px: neither measure depends on the light's size or on antialiasing; what is left is
        // the fill of the polygon by 256 discrete lens positions (about d / 16 = 1.5 px apart,
        // each a 6 px light) and the plateau's estimate from 30-40 pixels. Measured: within
        // 0.4 px.
        EXPECT_NEAR(b.areaDiameter, coc, 1.0);
        EXPECT_NEAR(fromWidth, coc, 1.0);
        // Centred where the pinhole sees the light (the image centre): the lens shifts copies,
        // symmetrically, never the whole bokeh.
        EXPECT_NEAR(b.centroid.x, 79.5, 0.25);
        EXPECT_NEAR(b.centroid.y, 59.5, 0.25);
    }
}

TEST_F(SyntheticSceneGL, RotationZeroPutsACornerUpAndThirtyAnEdge)
{
    // A far point (3 m, focus 1 m): the bokeh has the aperture's orientation. 64 rows are enough
    // for its 23.5 px; a 4 px light rounds the corners less than the 6 px one above.
    const auto bokeh = [](int blades, double rotation) {
        SyntheticSettings s = pointSettings(160, 64, 256);
        s.aperture.blades = blades;
        s.lens.bladeRotationDeg = rotation;
        SyntheticScene scene(pointScene(3.0, radiusForPixels(s, 3.0, 4.0)), s);
        return measureBokeh(scene.render(0).reference, {79.5, 31.5}, thinLensCocPixels(s.lens, s.width, 3.0), blades,
                            false);
    };
    // 5 degrees for the corner direction: a 23.5 px polygon on a pixel grid, built from 256
    // copies of a 4 px light. Measured within 2 degrees.
    const Bokeh hexagon0 = bokeh(6, 0.0);
    EXPECT_LT(angleDistance(hexagon0.cornerDeg, 90.0, 60.0), 5.0) << hexagon0.cornerDeg;
    const Bokeh hexagon30 = bokeh(6, 30.0);
    EXPECT_LT(angleDistance(hexagon30.cornerDeg, 120.0, 60.0), 5.0) << hexagon30.cornerDeg;
    // Just below the top: a corner is a few pixels wide there, an edge about half the diameter.
    EXPECT_LT(hexagon0.topWidth, 6);
    EXPECT_GT(hexagon30.topWidth, 8);

    // A pentagon tells up from down, which a hexagon cannot: rotation 0 must put its corner at
    // the top of the cv::Mat (row 0) and its flat edge (13.8 px) at the bottom, proving the
    // GL -> cv::Mat row flip; 90 degrees counter-clockwise turns that corner to the left.
    const Bokeh pentagon0 = bokeh(5, 0.0);
    EXPECT_LT(angleDistance(pentagon0.cornerDeg, 90.0, 72.0), 5.0) << pentagon0.cornerDeg;
    EXPECT_LT(pentagon0.topWidth, 6);
    EXPECT_GT(pentagon0.bottomWidth, 8);
    const Bokeh pentagon90 = bokeh(5, 90.0);
    EXPECT_LT(angleDistance(pentagon90.cornerDeg, 180.0, 72.0), 5.0) << pentagon90.cornerDeg;
    std::printf("[ FIGURE   ] corner directions (deg, y up): hexagon rot 0 -> %.1f (90 mod 60 = 30), rot 30 -> "
                "%.1f (0), pentagon rot 0 -> %.1f (90 mod 72 = 18), rot 90 -> %.1f (180 mod 72 = 36); below the top "
                "/ above the bottom: hexagon rot 0 %d / %d px, rot 30 %d / %d px, pentagon rot 0 %d / %d px\n",
                hexagon0.cornerDeg, hexagon30.cornerDeg, pentagon0.cornerDeg, pentagon90.cornerDeg, hexagon0.topWidth,
                hexagon0.bottomWidth, hexagon30.topWidth, hexagon30.bottomWidth, pentagon0.topWidth,
                pentagon0.bottomWidth);
}

TEST_F(SyntheticSceneGL, TinyApertureGivesThePinholeImage)
{
    // f/64 at 50 mm: the largest CoC in the spheres scene (the wall at 25 m, focus 1.8 m) is
    // 0.09 px at 160 px. With as many lens positions as pinhole sub-pixel offsets the two
    // images average the same offsets, so they differ only by the lens: shifts of <= 0.09 px.
    SyntheticSettings s;
    s.width = 160;
    s.height = 120;
    s.frames = 1;
    s.lens.fNumber = 64.0;
    s.aperture.samples = 64;
    s.pinholeSamples = 64;
    SyntheticScene scene(syntheticScene("spheres"), s);
    const SyntheticImages images = scene.render(0);
    const cv::Mat pinhole = luminance(images.frame.color), reference = luminance(images.reference);
    // The HDR highlights (up to 100) and 2 px around them are compared by their light only:
    // there even a 0.09 px blur moves tens of units across an edge pixel.
    cv::Mat highlights;
    cv::dilate(pinhole > 1.5f, highlights, cv::Mat::ones(5, 5, CV_8U));
    cv::Mat diff;
    cv::absdiff(pinhole, reference, diff);
    const double mean = cv::mean(diff, ~highlights)[0], level = cv::mean(pinhole, ~highlights)[0];
    double largest = 0.0;
    cv::minMaxLoc(diff, nullptr, &largest, nullptr, nullptr, ~highlights);
    cv::Mat weight;
    highlights.convertTo(weight, CV_32F, 1.0 / 255.0);
    const double lightRatio = cv::sum(reference.mul(weight))[0] / cv::sum(pinhole.mul(weight))[0];
    std::printf("[ FIGURE   ] f/64 reference vs pinhole, away from highlights: mean |diff| %.5f (mean level %.3f), "
                "max %.4f; light in the highlights: reference / pinhole %.4f\n",
                mean, level, largest, lightRatio);
    // Mean: 0.09 px shifts of edges of contrast ~1 on a few percent of the pixels give well
    // under 1% of the mean level (measured 0.5%). Max: a full-contrast edge moving 0.09 px
    // changes its pixel by 0.09; 0.1 allows that and no more.
    EXPECT_LT(mean, 0.01 * level);
    EXPECT_LT(largest, 0.1);
    // The highlights keep their light to 1% (their coverage of edge pixels is estimated from
    // 64 samples either way).
    EXPECT_NEAR(lightRatio, 1.0, 0.01);
}

TEST_F(SyntheticSceneGL, ReferenceKeepsTheLightsEnergy)
{
    // The lens only moves light about: summed over the bokeh, the reference holds what the
    // pinhole image holds. 64 lens positions are enough for a sum (not for a shape).
    SyntheticSettings s = pointSettings(160, 120, 64);
    s.pinholeSamples = 64;
    SyntheticScene scene(pointScene(3.0, radiusForPixels(s, 3.0, 6.0)), s);
    const SyntheticImages images = scene.render(0);
    const double pinhole = cv::sum(images.frame.color)[1], reference = cv::sum(images.reference)[1];
    std::printf("[ FIGURE   ] energy of a point light: reference / pinhole = %.4f\n", reference / pinhole);
    // 1%: the sphere's image is the same from every lens position up to its parallax (its
    // solid angle changes by (A / 2z)^2 ~ 1e-4); float sums of 64 renders are exact to 1e-6.
    EXPECT_NEAR(reference / pinhole, 1.0, 0.01);
}

TEST_F(SyntheticSceneGL, DepthIsPlanarAndNotAntialiased)
{
    // A wall facing the lens at 4 m and a thin panel at 2 m in front of it, seen through a
    // 20 mm lens: at the corners a ray is 1.4 times as long as the planar depth.
    SceneDescription scene;
    scene.name = "planes";
    SceneObject wall;
    wall.centre = {0.0f, 0.0f, -5.0f};
    wall.halfSize = {20.0f, 20.0f, 1.0f};
    scene.objects.push_back(wall);
    SceneObject panel;
    panel.centre = {0.3f, 0.1f, -2.0005f};
    panel.halfSize = {0.3f, 0.2f, 0.0005f};
    scene.objects.push_back(panel);
    scene.from = scene.to = {{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}};
    SyntheticSettings s;
    s.width = 96;
    s.height = 72;
    s.frames = 1;
    s.lens.focalLengthMm = 20.0;
    s.pinholeSamples = 4;
    SyntheticScene renderer(scene, s);
    const cv::Mat depth = renderer.render(0, false).frame.depth;
    ASSERT_EQ(depth.type(), CV_32FC1);
    int wallPixels = 0, panelPixels = 0, other = 0;
    for (int y = 0; y < depth.rows; ++y)
        for (int x = 0; x < depth.cols; ++x) {
            const float z = depth.at<float>(y, x);
            // Float32 depth interpolation is exact to ~1e-6 relative; the panel's 1 mm thickness
            // may show as a sliver of its side at its edges.
            if (std::abs(z - 4.0f) < 1e-4f)
                ++wallPixels;
            else if (std::abs(z - 2.0f) < 2e-3f)
                ++panelPixels;
            else
                ++other;
        }
    EXPECT_EQ(other, 0) << "depth values that are neither plane: blended or ray lengths";
    EXPECT_GT(panelPixels, 100);
    EXPECT_GT(wallPixels, 4000);
    // The panel is at the upper right of the image (x and y positive, y up): rows near the top.
    EXPECT_NEAR(depth.at<float>(depth.rows / 2 - 4, depth.cols / 2 + 10), 2.0f, 2e-3f);
    EXPECT_NEAR(depth.at<float>(depth.rows / 2 + 8, depth.cols / 2 + 10), 4.0f, 1e-4f);
}

TEST_F(SyntheticSceneGL, SourceYieldsTheClipAndThePullMovesTheFocus)
{
    SyntheticSettings s;
    s.width = 160;
    s.height = 120;
    s.frames = 4;
    s.pinholeSamples = 1;
    s.aperture.samples = 32;
    s.lens.fNumber = 1.4;
    SyntheticSource source(syntheticScene("spheres"), s);
    ASSERT_EQ(source.frameCount(), std::size_t{4});
    EXPECT_EQ(source.frameRate(), 30.0);
    EXPECT_NE(source.describe().find("spheres"), std::string::npos);
    std::size_t count = 0;
    while (auto frame = source.next()) {
        EXPECT_EQ(frame->index, count);
        EXPECT_EQ(frame->name, fmt::format("synthetic/spheres/{:04d}", count));
        EXPECT_DOUBLE_EQ(frame->timestampS, static_cast<double>(count) / 30.0);
        EXPECT_EQ(frame->color.type(), CV_32FC3);
        EXPECT_EQ(frame->depth.type(), CV_32FC1);
        EXPECT_TRUE(test::allFinite(frame->color));
        ++count;
    }
    EXPECT_EQ(count, 4u);
    EXPECT_DOUBLE_EQ(source.lensAt(0).focusM, 1.8);
    EXPECT_DOUBLE_EQ(source.lensAt(3).focusM, 12.0);

    // The pull moves the sharpness: near surfaces are sharper at the first frame (focus 1.8 m)
    // than at the last (12 m), far ones the other way round. Sharpness: mean |Laplacian| of the
    // reference over the pixels of each depth range.
    const auto sharpness = [&](std::size_t index) {
        const SyntheticImages images = source.scene().render(index);
        cv::Mat laplacian;
        cv::Laplacian(luminance(cv::min(images.reference, 1.0)), laplacian, CV_32F);
        laplacian = cv::abs(laplacian);
        const cv::Mat nearMask = images.frame.depth < 2.5f, farMask = images.frame.depth > 10.0f;
        return std::pair{cv::mean(laplacian, nearMask)[0], cv::mean(laplacian, farMask)[0]};
    };
    const auto [near0, far0] = sharpness(0);
    const auto [near3, far3] = sharpness(3);
    std::printf("[ FIGURE   ] mean |Laplacian|, near / far: focus 1.8 m %.4f / %.4f, focus 12 m %.4f / %.4f\n", near0,
                far0, near3, far3);
    EXPECT_GT(near0, 1.5 * near3);
    EXPECT_GT(far3, 1.5 * far0);
}

TEST_F(SyntheticSceneGL, TheCyclesTruthAgreesOnCocSizeAndOrientation)
{
    // The Blender scene's highlights on its wall (25 m; the scene's camera: 85 mm f/1.4 focused
    // at 5 m, 36 mm over 640 px) measured in the Cycles truth, and a point at 25 m rendered by
    // the synthetic reference with the same lens (640 px wide, so the CoC is the same 14.9 px;
    // 48 rows are enough).
    const LensSettings lens = blenderSpheresLens();
    const double coc = thinLensCocPixels(lens, 640, 25.0);

    const auto dir = test::dataDir() / "blender_spheres";
    const cv::Mat color = readColor(dir / "color_linear.exr");
    const cv::Mat depth = readDepth(dir / "depth.exr", 1000.0);
    const cv::Mat truth = readColor(dir / "truth_f1.4_focus5_linear.exr");
    cv::Mat brightest;
    cv::reduce(color.reshape(1, color.rows * color.cols), brightest, 1, cv::REDUCE_MAX);
    brightest = brightest.reshape(1, color.rows);
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(brightest > 5.0f, labels, stats, centroids);
    std::vector<double> ratios, cornerOffsets;
    for (int i = 1; i < n; ++i) {
        const cv::Point2d c(centroids.at<double>(i, 0), centroids.at<double>(i, 1));
        const float z = depth.at<float>(static_cast<int>(c.y), static_cast<int>(c.x));
        // On the wall, and small: the lights at 25 m are 5 px wide, a third of the CoC.
        if (std::abs(z - 25.0f) > 0.5f || stats.at<int>(i, cv::CC_STAT_AREA) > 40)
            continue;
        const Bokeh b = measureBokeh(truth, c, coc, 6, true);
        ratios.push_back(b.areaDiameter / coc);
        cornerOffsets.push_back(angleDistance(b.cornerDeg, 90.0, 60.0));
    }
    ASSERT_GE(ratios.size(), 5u) << "highlights on the wall of the Blender scene";
    double meanRatio = 0.0, meanOffset = 0.0;
    for (std::size_t i = 0; i < ratios.size(); ++i) {
        meanRatio += ratios[i] / static_cast<double>(ratios.size());
        meanOffset += cornerOffsets[i] / static_cast<double>(ratios.size());
    }

    SyntheticSettings s;
    s.width = 640;
    s.height = 48;
    s.frames = 1;
    s.lens = lens;
    s.focusPull = false;
    s.aperture.samples = 256;
    SyntheticScene scene(pointScene(25.0, radiusForPixels(s, 25.0, 5.0)), s);
    const Bokeh ours = measureBokeh(scene.render(0).reference, {319.5, 23.5}, coc, 6, false);

    // Cycles derives the field of view from the focal length, and so does this lens
    // (FieldOfView::FocalLength, for the filter and for the synthetic camera): the CoC is
    // (S1 - f) / S1 = 0.983 of the lens formula's with the sensor at the image distance v.
    LensSettings atImageDistance = lens;
    atImageDistance.fieldOfView = FieldOfView::ImageDistance;
    const double lensFormula = thinLensCocPixels(atImageDistance, 640, 25.0);
    std::printf("[ FIGURE   ] CoC at 25 m: %.2f px with the field of view from f (%.2f px from v); Cycles truth "
                "%.3f x (%zu highlights); synthetic %.3f x; corner %.1f deg from straight up in Cycles, %.1f in "
                "ours\n",
                coc, lensFormula, meanRatio, ratios.size(), ours.areaDiameter / coc, meanOffset,
                angleDistance(ours.cornerDeg, 90.0, 60.0));
    EXPECT_NEAR(coc / lensFormula, (lens.focusM - 0.085) / lens.focusM, 1e-6);
    // Sizes: the Cycles highlights scatter by +-1.5% (5 px lights on a brick texture,
    // path-tracing noise); the mean of six is good to about 1% (measured 0.996; 0.980 of the
    // lens formula's CoC with the sensor at v).
    EXPECT_NEAR(meanRatio, 1.0, 0.015);
    EXPECT_NEAR(ours.areaDiameter / coc, 1.0, 0.03);
    // Orientation: a corner up in both (a flat top would be 30 degrees off). Ours is exactly up
    // by construction; the estimator reads 3.0 to 5.1 degrees on this 15 px bokeh as its size
    // moves by a quarter pixel between the two camera conventions, so 7.5 leaves it room.
    EXPECT_LT(meanOffset, 10.0);
    EXPECT_LT(angleDistance(ours.cornerDeg, 90.0, 60.0), 7.5);
}

// `defocus --demo`: the clip is rendered and blurred frame by frame (3 frames of "edges" at
// 640x480 keep this to a second or two). Defect caught: a demo that writes its frames unblurred
// (a lens or a preset not passed on, every frame taken as in focus). The same frames written
// with --view input are the unblurred reference: the result must differ from them and have lost
// most of their fine detail (the variance of the Laplacian: measured 0.02, 0.13 and 0.25 of the
// input's over the focus pull; half allowed).
TEST_F(SyntheticSceneGL, DemoBlursASyntheticClipWithNoInput)
{
    const auto dir = test::scratchDir("synthetic-demo");
    const auto run = [&](const std::string& view, const std::string& folder) {
        std::filesystem::create_directories(dir / folder);
        const std::string command = std::string(DEFOCUS_BINARY_DIR) +
                                    "/defocus --demo --demo-scene edges --frames 3 --f-number 1.4 -q --view " + view +
                                    " -o " + (dir / folder).string() + "/";
        EXPECT_EQ(std::system(command.c_str()), 0) << command;
        std::vector<std::filesystem::path> frames;
        for (const auto& entry : std::filesystem::directory_iterator(dir / folder))
            if (entry.path().extension() == ".png")
                frames.push_back(entry.path());
        std::sort(frames.begin(), frames.end());
        return frames;
    };
    const auto blurred = run("composite", "out"), input = run("input", "input");
    ASSERT_EQ(blurred.size(), 3u);
    ASSERT_EQ(input.size(), 3u);
    const auto detail = [](const std::filesystem::path& file) {
        cv::Mat gray, laplacian;
        cv::cvtColor(cv::imread(file.string()), gray, cv::COLOR_BGR2GRAY);
        cv::Laplacian(gray, laplacian, CV_32F);
        cv::Scalar mean, stddev;
        cv::meanStdDev(laplacian, mean, stddev);
        return stddev[0] * stddev[0];
    };
    for (std::size_t i = 0; i < 3; ++i) {
        const double ratio = detail(blurred[i]) / detail(input[i]);
        std::printf("[ demo ] frame %zu: detail %.3f of the input's\n", i, ratio);
        EXPECT_LT(ratio, 0.5) << blurred[i];
    }
}

} // namespace
} // namespace defocus
