// SPDX-License-Identifier: LGPL-2.1-or-later
// Depth preparation without GL: nearest resize, push-pull hole filling, centre depth.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "filter/DepthPrep.hpp"

namespace defocus {
namespace {

TEST(DepthPrep, ValidPixelsAreKeptExactlyAndHolesFilledFromNeighbours)
{
    cv::Mat depth(40, 60, CV_32F, cv::Scalar(2.0f));
    depth(cv::Rect(30, 0, 30, 40)).setTo(4.0f);
    depth.at<float>(10, 10) = 0.0f;                                      // hole in the 2 m side
    depth.at<float>(11, 10) = std::numeric_limits<float>::quiet_NaN();   // NaN
    depth.at<float>(20, 45) = -1.0f;                                     // negative, 4 m side
    depth.at<float>(21, 45) = std::numeric_limits<float>::infinity();
    depth.at<float>(22, 45) = 1e-40f;                                    // denormal
    const auto prepared = prepareDepth(depth, depth.size(), 9.0f);
    EXPECT_NEAR(prepared.invalidFraction, 5.0 / (40.0 * 60.0), 1e-12);
    EXPECT_TRUE(cv::checkRange(prepared.metres, true, nullptr, kMinValidDepthM, 1e30));
    // Far from the 2|4 m edge a hole sees only its own side (push-pull averages neighbours).
    EXPECT_NEAR(prepared.metres.at<float>(10, 10), 2.0f, 1e-4f);
    EXPECT_NEAR(prepared.metres.at<float>(11, 10), 2.0f, 1e-4f);
    EXPECT_NEAR(prepared.metres.at<float>(21, 45), 4.0f, 1e-4f);
    EXPECT_EQ(prepared.metres.at<float>(5, 5), 2.0f);
    EXPECT_EQ(prepared.metres.at<float>(5, 50), 4.0f);
}

TEST(DepthPrep, LargeHoleIsFilledWithValuesBetweenItsBorders)
{
    cv::Mat depth(64, 64, CV_32F);
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x)
            depth.at<float>(y, x) = 1.0f + static_cast<float>(x) / 32.0f; // 1..3 m ramp
    depth(cv::Rect(16, 16, 32, 32)).setTo(0.0f);
    const auto prepared = prepareDepth(depth, depth.size(), 9.0f);
    double lo = 0, hi = 0;
    cv::minMaxLoc(prepared.metres(cv::Rect(16, 16, 32, 32)), &lo, &hi);
    EXPECT_GE(lo, 1.0 + 15.0 / 32.0 - 1e-3);
    EXPECT_LE(hi, 1.0 + 48.0 / 32.0 + 1e-3);
}

TEST(DepthPrep, ResizeIsNearestSoNoDepthIsInventedAcrossEdges)
{
    cv::Mat depth(24, 32, CV_32F, cv::Scalar(1.0f));
    depth(cv::Rect(16, 0, 16, 24)).setTo(10.0f);
    const auto prepared = prepareDepth(depth, {640, 480}, 5.0f);
    ASSERT_EQ(prepared.metres.size(), cv::Size(640, 480));
    for (int y = 0; y < 480; y += 7)
        for (int x = 0; x < 640; x += 3) {
            const float z = prepared.metres.at<float>(y, x);
            EXPECT_TRUE(z == 1.0f || z == 10.0f) << z;
        }
}

TEST(DepthPrep, NoValidDepthGivesTheFallback)
{
    cv::Mat depth(10, 10, CV_32F, cv::Scalar(0.0f));
    const auto prepared = prepareDepth(depth, depth.size(), 3.5f);
    EXPECT_EQ(prepared.invalidFraction, 1.0);
    EXPECT_EQ(cv::countNonZero(prepared.metres != 3.5f), 0);
    const auto none = prepareDepth(cv::Mat(), {8, 6}, 3.5f);
    EXPECT_EQ(none.metres.size(), cv::Size(8, 6));
    EXPECT_EQ(cv::countNonZero(none.metres != 3.5f), 0);
}

// A depth frame of `size` with a ramp of depths and holes where `seed` puts them (a share of
// about `holes`), and now and then a block of holes that only coarse levels fill.
cv::Mat depthWithHoles(cv::Size size, unsigned seed, double holes)
{
    cv::Mat depth(size, CV_32F);
    cv::RNG rng(seed);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x)
            depth.at<float>(y, x) = rng.uniform(0.0, 1.0) < holes ? 0.0f : 0.5f + 0.01f * static_cast<float>(x + y);
    if (holes > 0.0)
        depth(cv::Rect(size.width / 4, size.height / 3, size.width / 3, size.height / 4)).setTo(0.0f);
    return depth;
}

// Buffers kept from frame to frame must not carry one frame into the next: each frame through
// one workspace, whatever the frame before it (another size, other holes, none, all), must equal
// the same frame through fresh buffers, to the bit.
TEST(DepthPrepWorkspace, EachFrameEqualsItsOwnFreshResult)
{
    struct Step {
        cv::Mat depth;
        cv::Size size;
    };
    const std::vector<Step> steps{
        {depthWithHoles({64, 48}, 1, 0.3), {64, 48}},
        {depthWithHoles({64, 48}, 2, 0.05), {64, 48}},
        {depthWithHoles({37, 29}, 3, 0.3), {37, 29}},   // smaller, odd: fewer and odd levels
        {depthWithHoles({32, 24}, 4, 0.2), {64, 48}},   // resized to the frame
        {depthWithHoles({64, 48}, 5, 0.0), {64, 48}},   // no holes: no pyramid
        {cv::Mat(48, 64, CV_32F, cv::Scalar(0.0f)), {64, 48}}, // no valid depth
        {cv::Mat(), {64, 48}},                                  // no depth
        {depthWithHoles({64, 48}, 1, 0.3), {64, 48}},
    };
    DepthPrepWorkspace workspace;
    PreparedDepth kept;
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const PreparedDepth fresh = prepareDepth(steps[i].depth, steps[i].size, 2.5f);
        prepareDepth(steps[i].depth, steps[i].size, 2.5f, workspace, kept);
        ASSERT_EQ(kept.metres.size(), fresh.metres.size()) << "step " << i;
        EXPECT_EQ(kept.invalidFraction, fresh.invalidFraction) << "step " << i;
        EXPECT_EQ(cv::norm(kept.metres, fresh.metres, cv::NORM_INF), 0.0) << "step " << i;
    }
}

// The output is written in place from frame to frame, not into a buffer taken while the last
// one is still alive (as assigning a fresh result would), except where the caller still holds
// the last one: that one keeps its depths.
TEST(DepthPrepWorkspace, OutputIsReusedUnlessTheCallerHoldsIt)
{
    DepthPrepWorkspace workspace;
    PreparedDepth out;
    prepareDepth(depthWithHoles({64, 48}, 1, 0.3), {64, 48}, 2.5f, workspace, out);
    const uchar* first = out.metres.data;
    const uchar* firstLevel = workspace.levels.at(1).value.data;
    prepareDepth(depthWithHoles({64, 48}, 2, 0.3), {64, 48}, 2.5f, workspace, out);
    EXPECT_EQ(out.metres.data, first);
    EXPECT_EQ(workspace.levels.at(1).value.data, firstLevel);

    const cv::Mat held = out.metres;
    const cv::Mat heldCopy = held.clone();
    prepareDepth(depthWithHoles({64, 48}, 3, 0.3), {64, 48}, 2.5f, workspace, out);
    EXPECT_NE(out.metres.data, held.data);
    EXPECT_EQ(cv::norm(held, heldCopy, cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(out.metres, heldCopy, cv::NORM_INF), 0.0);
}

TEST(DepthPrep, CentreDepthIsTheMedianOfValidCentrePixels)
{
    cv::Mat depth(100, 100, CV_32F, cv::Scalar(9.0f));
    depth(cv::Rect(45, 45, 10, 10)).setTo(1.5f);
    depth.at<float>(50, 50) = 0.0f;
    EXPECT_FLOAT_EQ(centreDepth(depth, 0.1, 7.0f), 1.5f);
    depth(cv::Rect(45, 45, 10, 10)).setTo(0.0f);
    EXPECT_FLOAT_EQ(centreDepth(depth, 0.1, 7.0f), 7.0f);
}

TEST(DepthPrep, LightEdgesTakeTheLightsDepthDecidedOnTheDepthAsItWas)
{
    // Catches the edge rule changing pixels it should not, or not changing those it should: a
    // change applied during the scan (it then spreads from the light's edge outwards, pixel by
    // pixel), a band of rows left out, a pixel moved to a dimmer neighbour's depth, or one kept at
    // its own beside a brighter, farther light (an occluder's edge in front of a light). A 64 x 48
    // float frame at 10 m: a light of 50 at 2 m in rows 20-22, columns 30-32, a ring of 10 around
    // it and a second ring of 2 (both above white) at the background's depth: the first ring
    // takes 2 m, the second keeps 10 m (its brightest neighbour, the first ring, was at 10 m). In
    // row 40: a pixel of 50 at 10 m beside a brighter one of 60 at 1 m takes 1 m; a pixel of 50 at
    // 1 m beside one of 60 at 10 m takes 10 m; one of 60 at 1 m beside one of 50 at 10 m keeps 1 m.
    cv::Mat color(48, 64, CV_32FC3, cv::Scalar::all(0.1));
    cv::Mat depth(color.size(), CV_32F, cv::Scalar(10.0f));
    const auto ring = [&](int radius, float level) {
        for (int y = 21 - radius; y <= 21 + radius; ++y)
            for (int x = 31 - radius; x <= 31 + radius; ++x)
                if (std::max(std::abs(y - 21), std::abs(x - 31)) == radius)
                    color.at<cv::Vec3f>(y, x) = cv::Vec3f::all(level);
    };
    ring(3, 2.0f);
    ring(2, 10.0f);
    color(cv::Rect(30, 20, 3, 3)).setTo(cv::Scalar::all(50.0));
    depth(cv::Rect(30, 20, 3, 3)).setTo(2.0f);
    color.at<cv::Vec3f>(40, 10) = cv::Vec3f::all(50.0f);
    color.at<cv::Vec3f>(40, 11) = cv::Vec3f::all(60.0f);
    depth.at<float>(40, 11) = 1.0f;
    color.at<cv::Vec3f>(40, 50) = cv::Vec3f::all(50.0f);
    depth.at<float>(40, 50) = 1.0f;
    color.at<cv::Vec3f>(40, 51) = cv::Vec3f::all(60.0f);
    color.at<cv::Vec3f>(40, 20) = cv::Vec3f::all(60.0f);
    depth.at<float>(40, 20) = 1.0f;
    color.at<cv::Vec3f>(40, 21) = cv::Vec3f::all(50.0f);
    cv::Mat expected = depth.clone();
    for (int y = 19; y <= 23; ++y)
        for (int x = 29; x <= 33; ++x)
            if (std::max(std::abs(y - 21), std::abs(x - 31)) == 2)
                expected.at<float>(y, x) = 2.0f;
    expected.at<float>(40, 10) = 1.0f;
    expected.at<float>(40, 50) = 10.0f;
    expected.at<float>(40, 21) = 1.0f; // the dimmer one beside it, at 10 m, takes the brighter's 1 m
    cv::Mat metres = depth.clone();
    const std::size_t changed = putLightEdgesAtTheirLightsDepth(color, metres);
    EXPECT_EQ(changed, 19u);
    EXPECT_EQ(cv::norm(metres, expected, cv::NORM_INF), 0.0);
}

TEST(DepthPrep, ASliverOfALightBesideANearBarTakesTheLightsDepth)
{
    // Catches a light's sliver beside a bar kept at the bar's depth when its brightest pixel's
    // depth sample fell on the bar: the sliver then took the bar's blur, a pale hexagon as wide as
    // that blur where the lens shows a sharp dot (the railing-lights scene of the corpus). Also
    // catches the rule reaching too far: a light's own edge in front of a background (its inside
    // bright) or a light one pixel wide (the background on both sides) sent to the background.
    // A 64 x 48 frame of 0.1 at 10 m with a bar at 1 m in columns 5-12; in rows 20-22 the bar's
    // last column is a light's edge of 60, the column beyond it the light's 50. In row 30 a light
    // at 1 m in columns 38-40 (55, 55, 60) before a pixel of 50 at 10 m; in row 36 one pixel of
    // 60 at 1 m between pixels of 50 at 10 m.
    cv::Mat color(48, 64, CV_32FC3, cv::Scalar::all(0.1));
    cv::Mat depth(color.size(), CV_32F, cv::Scalar(10.0f));
    depth(cv::Rect(5, 0, 8, 48)).setTo(1.0f);
    color(cv::Rect(12, 20, 1, 3)).setTo(cv::Scalar::all(60.0));
    color(cv::Rect(13, 20, 1, 3)).setTo(cv::Scalar::all(50.0));
    color(cv::Rect(38, 30, 2, 1)).setTo(cv::Scalar::all(55.0));
    color.at<cv::Vec3f>(30, 40) = cv::Vec3f::all(60.0f);
    color.at<cv::Vec3f>(30, 41) = cv::Vec3f::all(50.0f);
    depth(cv::Rect(38, 30, 3, 1)).setTo(1.0f);
    color(cv::Rect(20, 36, 3, 1)).setTo(cv::Scalar::all(50.0));
    color.at<cv::Vec3f>(36, 21) = cv::Vec3f::all(60.0f);
    depth.at<float>(36, 21) = 1.0f;
    cv::Mat expected = depth.clone();
    expected(cv::Rect(12, 20, 1, 3)).setTo(10.0f); // the light's edge sampled on the bar
    expected.at<float>(30, 41) = 1.0f;              // the near light's antialiased edge
    expected.at<float>(36, 20) = 1.0f;              // the one-pixel light's edges
    expected.at<float>(36, 22) = 1.0f;
    cv::Mat metres = depth.clone();
    EXPECT_EQ(putLightEdgesAtTheirLightsDepth(color, metres), 6u);
    EXPECT_EQ(cv::norm(metres, expected, cv::NORM_INF), 0.0)
        << "bar edge " << metres(cv::Rect(11, 19, 4, 5)) << "\nnear light " << metres(cv::Rect(37, 29, 6, 3))
        << "\none pixel " << metres(cv::Rect(19, 35, 5, 3));
}

// The all-in-focus check's valid range, against a plain loop over the pixels. Defects caught: a
// hole (0, NaN, +-Inf, negative, below kMinValidDepthM) taken as a depth or a depth as a hole, a
// lane or row end left out (widths that are not a multiple of the SIMD lanes, a row shorter
// than them), a 16-bit depth of 65535 or 1 lost, a view's padding read, a frame of holes given
// a range.
TEST(ValidDepthRange, IsWhatALoopOverThePixelsFinds)
{
    cv::RNG rng(7);
    for (const cv::Size size : {cv::Size(1, 1), cv::Size(7, 3), cv::Size(16, 2), cv::Size(641, 37), cv::Size(1920, 9)})
        for (const int type : {CV_32FC1, CV_16UC1})
            for (const double holeShare : {0.0, 0.3, 1.0}) {
                SCOPED_TRACE(testing::Message() << size << (type == CV_32FC1 ? " float" : " 16-bit") << ", holes "
                                                << holeShare);
                // A view inside a larger image: rows with padding after them.
                cv::Mat whole(size.height + 2, size.width + 5, type);
                cv::Mat depth = whole(cv::Rect(2, 1, size.width, size.height));
                const float strange[] = {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN(),
                                         std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                                         kMinValidDepthM, 0.5f * kMinValidDepthM};
                whole.setTo(type == CV_32FC1 ? cv::Scalar(0.01) : cv::Scalar(1)); // padding: nearer than all
                for (int y = 0; y < depth.rows; ++y)
                    for (int x = 0; x < depth.cols; ++x) {
                        const bool hole = rng.uniform(0.0, 1.0) < holeShare;
                        if (type == CV_32FC1)
                            depth.at<float>(y, x) = hole ? strange[rng.uniform(0, 7)] : rng.uniform(0.2f, 9.0f);
                        else
                            depth.at<std::uint16_t>(y, x) =
                                hole ? 0 : static_cast<std::uint16_t>(rng.uniform(2, 65535 + 1));
                    }
                if (type == CV_16UC1 && holeShare < 1.0 && depth.total() > 2) {
                    depth.at<std::uint16_t>(0, depth.cols - 1) = 65535;
                    depth.at<std::uint16_t>(depth.rows - 1, depth.cols / 2) = 1;
                }
                float expectLo = -7.0f, expectHi = -7.0f; // "unchanged"
                float low = std::numeric_limits<float>::max(), high = std::numeric_limits<float>::lowest();
                std::size_t invalid = 0;
                for (int y = 0; y < depth.rows; ++y)
                    for (int x = 0; x < depth.cols; ++x) {
                        const float z = type == CV_32FC1 ? depth.at<float>(y, x) : depth.at<std::uint16_t>(y, x);
                        const bool valid = type == CV_32FC1 ? isValidDepth(z) : z > 0.0f;
                        if (valid) {
                            low = std::min(low, z);
                            high = std::max(high, z);
                        } else {
                            ++invalid;
                        }
                    }
                const double units = type == CV_32FC1 ? 1.0 : 5000.0;
                if (low <= high) {
                    expectLo = static_cast<float>(low / units);
                    expectHi = static_cast<float>(high / units);
                }
                float lo = -7.0f, hi = -7.0f;
                const double share = validDepthRange(depth, units, lo, hi);
                EXPECT_EQ(lo, expectLo);
                EXPECT_EQ(hi, expectHi);
                EXPECT_DOUBLE_EQ(share, static_cast<double>(invalid) / static_cast<double>(depth.total()));
            }
    float lo = -7.0f, hi = -7.0f;
    EXPECT_EQ(validDepthRange(cv::Mat(), 1.0, lo, hi), 1.0) << "no depth: all of it is no measurement";
    EXPECT_EQ(lo, -7.0f);
}

} // namespace
} // namespace defocus
