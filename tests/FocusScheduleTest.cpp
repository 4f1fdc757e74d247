// SPDX-License-Identifier: LGPL-2.1-or-later
// Focus over a clip (samples/FocusSchedule): keyed pulls eased in dioptres, the depth under a
// point, tracking focus and the errors for bad --focus values, frame by frame.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "samples/FocusSchedule.hpp"

namespace defocus {
namespace {

Frame frameAt(float depthM, std::size_t index = 0)
{
    Frame frame;
    frame.color = cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(128));
    frame.depth = cv::Mat(48, 64, CV_32FC1, cv::Scalar(depthM));
    frame.index = index;
    return frame;
}

// Defect caught: a pull interpolated in metres (it would rush through the near distances and
// crawl at the far end), not eased (a jump in speed at each key), or keys held at the wrong side.
TEST(FocusSchedule, PullIsEasedInDioptresAndHeldOutsideTheKeys)
{
    const FocusSchedule pull = FocusSchedule::parse("0s:1.2,2s:3.5");
    const double d0 = 1.0 / 1.2, d1 = 1.0 / 3.5;
    // Per frame at 4 Hz: (time, smoothstep of the way), from 3u^2 - 2u^3 worked by hand.
    const std::vector<std::pair<double, double>> frames{{-1.0, 0.0},  {0.0, 0.0},      {0.5, 0.15625}, {1.0, 0.5},
                                                        {1.5, 0.84375}, {2.0, 1.0}, {3.0, 1.0}};
    for (const auto& [t, eased] : frames)
        EXPECT_NEAR(pull.focusAt(t), 1.0 / (d0 + eased * (d1 - d0)), 1e-9) << "t = " << t;
    EXPECT_NEAR(pull.focusAt(1.0), 1.7872, 1e-4); // half way in dioptres, not (1.2 + 3.5) / 2 = 2.35 m
}

// Defect caught: a pull to infinity giving NaN or a finite distance at its end.
TEST(FocusSchedule, PullToInfinity)
{
    const FocusSchedule pull = FocusSchedule::parse("0s:1,1s:inf");
    EXPECT_DOUBLE_EQ(pull.focusAt(0.5), 2.0); // half way from 1 D to 0 D
    EXPECT_TRUE(std::isinf(pull.focusAt(1.0)));
}

// Defect caught: malformed keys accepted silently (a missing unit read as frames, keys out of order).
TEST(FocusSchedule, BadKeysAreRefusedNamingTheKey)
{
    for (const char* bad : {"0:1.2", "0s:1.2,2s", "1s:2,0.5s:3", "0s:-1", "0s:abc", "xs:1"}) {
        try {
            FocusSchedule::parse(bad);
            ADD_FAILURE() << bad << " was accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("--focus key"), std::string::npos) << e.what();
        }
    }
}

// Defect caught: the point's window taking holes as depth 0 (a near focus), or the depth map's
// own coordinates used when it is smaller than the colour.
TEST(FocusPoint, MedianOfTheValidDepthsAroundThePoint)
{
    cv::Mat depth(24, 32, CV_32FC1, cv::Scalar(5.0f)); // half the colour's 64x48
    depth(cv::Rect(20, 4, 8, 8)).setTo(1.5f);
    depth.at<float>(8, 24) = 0.0f;                               // a hole in the window
    depth.at<float>(7, 23) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_DOUBLE_EQ(*depthAtPoint(depth, {64, 48}, {48, 16}), 1.5); // colour pixel 48,16 = depth 24,8
    EXPECT_DOUBLE_EQ(*depthAtPoint(depth, {64, 48}, {8, 40}), 5.0);
    EXPECT_FALSE(depthAtPoint(cv::Mat(24, 32, CV_32FC1, cv::Scalar(0.0f)), {64, 48}, {8, 8}));
    EXPECT_EQ(parsePoint("320,240"), cv::Point2d(320, 240));
    EXPECT_THROW(parsePoint("320"), std::invalid_argument);
    EXPECT_THROW(parsePoint("-1,2"), std::invalid_argument);
}

// Defect caught: 'auto' measured again on later frames (the focus would jump with the scene), or
// a point ignored.
TEST(FocusControl, AutoKeepsTheFirstFramesDepthAtThePoint)
{
    Frame first = frameAt(3.0f);
    first.depth(cv::Rect(0, 0, 10, 10)).setTo(0.8f);
    FocusControl control("auto", cv::Point2d(4, 4));
    EXPECT_FLOAT_EQ(static_cast<float>(control.focusFor(first, 0.0, 0.0)), 0.8f);
    EXPECT_FLOAT_EQ(static_cast<float>(control.focusFor(frameAt(6.0f, 1), 0.033, 0.033)), 0.8f);
}

// Defect caught: 'track' jumping to each frame's depth (no time constant) or never moving.
// Frame by frame: the first measurement is taken at once, then a step from 1 m to 2 m is followed
// by the critically damped spring: after 4.7 time constants 95 % of the way in dioptres, no overshoot.
TEST(FocusControl, TrackFollowsAStepWithTheAutofocusTimeConstant)
{
    FocusTrackerOptions settings;
    settings.timeConstantS = 0.25;
    FocusControl control("track", std::nullopt, settings);
    const double dt = 1.0 / 30.0;
    EXPECT_NEAR(control.focusFor(frameAt(1.0f, 0), 0.0, dt), 1.0, 1e-9);
    double previous = 1.0;
    double focus = 1.0;
    for (int k = 1; k <= 36; ++k) { // 1.2 s = 4.8 tau
        focus = control.focusFor(frameAt(2.0f, static_cast<std::size_t>(k)), k * dt, dt);
        EXPECT_GE(focus, previous - 1e-12) << "frame " << k; // monotonic, no overshoot past 2 m
        EXPECT_LE(focus, 2.0 + 1e-9) << "frame " << k;
        previous = focus;
        if (k == 1) {
            EXPECT_LT(focus, 1.1) << "a step is followed, not jumped to";
        }
    }
    EXPECT_GT((1.0 - 1.0 / focus) / (1.0 - 0.5), 0.95);
}

// Defect caught: a bad --focus accepted, or --focus-point with a fixed focus silently ignored.
TEST(FocusControl, BadFocusValuesAreRefused)
{
    EXPECT_THROW(FocusControl("near", std::nullopt), std::invalid_argument);
    EXPECT_THROW(FocusControl("-2", std::nullopt), std::invalid_argument);
    EXPECT_THROW(FocusControl("1.5", cv::Point2d(1, 1)), std::invalid_argument);
    EXPECT_TRUE(std::isinf(FocusControl("inf", std::nullopt).focusFor(frameAt(1.0f), 0, 0)));
    FocusControl keyed("0s:1,1s:2", std::nullopt);
    EXPECT_DOUBLE_EQ(keyed.focusFor(frameAt(9.0f), 1.0, 0.0), 2.0);
}

} // namespace
} // namespace defocus
