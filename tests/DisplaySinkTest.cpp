// SPDX-License-Identifier: LGPL-2.1-or-later
// The display sink's logic without a window: what each key does to the live controls (with
// clamping through validate()), and the picture the window would show (frame + HUD band).
// The window itself is tested under Xvfb by scripts/display-test.sh (CTest label "display").
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "sinks/DisplaySink.hpp"

namespace defocus {
namespace {

TEST(DisplayControls, NumberKeysChooseTheLabViewsThenDepthAndCoc)
{
    LiveControls controls;
    for (int i = 0; i < 7; ++i) {
        const auto outcome = applyKey(controls, '1' + i, 2.0);
        EXPECT_TRUE(outcome.handled);
        EXPECT_EQ(controls.view, kAllViews[i]);
    }
    EXPECT_EQ(controls.view, View::Coc);
}

TEST(DisplayControls, FNumberMovesByThirdStopsOnTheStandardScale)
{
    LiveControls controls; // f/2
    applyKey(controls, '+', 2.0);
    EXPECT_NEAR(controls.lens.fNumber, std::exp2(7.0 / 6.0), 1e-12); // 2.24
    applyKey(controls, '+', 2.0);
    applyKey(controls, '=', 2.0); // the unshifted '+' key
    EXPECT_NEAR(controls.lens.fNumber, std::sqrt(8.0), 1e-12);     // f/2.8: one stop
    applyKey(controls, '-', 2.0);
    applyKey(controls, '-', 2.0);
    applyKey(controls, '_', 2.0);
    EXPECT_NEAR(controls.lens.fNumber, 2.0, 1e-12);
}

TEST(DisplayControls, ImpossibleFNumbersAreClampedWithAWarning)
{
    LiveControls controls;
    controls.lens.fNumber = 64.0;
    auto outcome = applyKey(controls, '+', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.fNumber, 64.0);
    ASSERT_EQ(outcome.issues.size(), 1u);
    EXPECT_EQ(outcome.issues[0].parameter, "--f-number");
    controls.lens.fNumber = 0.7;
    outcome = applyKey(controls, '-', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.fNumber, 0.7);
    ASSERT_EQ(outcome.issues.size(), 1u);
    // A step inside the range says nothing.
    EXPECT_TRUE(applyKey(controls, '+', 2.0).issues.empty());
}

TEST(DisplayControls, BracketsChangeMaxCocAndClampAtZero)
{
    LiveControls controls; // 32 px
    applyKey(controls, ']', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.maxCocPx, 34.0);
    controls.lens.maxCocPx = 1.0;
    applyKey(controls, '[', 2.0);
    applyKey(controls, '[', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.maxCocPx, 0.0);
    const auto outcome = applyKey(controls, '[', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.maxCocPx, 0.0);
    ASSERT_EQ(outcome.issues.size(), 1u);
    EXPECT_EQ(outcome.issues[0].parameter, "--max-coc");
}

TEST(DisplayControls, JWidensAndLNarrowsTheFocalRangeWhichStaysAroundTheFocus)
{
    LiveControls controls;
    EXPECT_EQ(controls.lens.model, CocModel::ThinLens);
    applyKey(controls, 'j', 2.0);
    EXPECT_EQ(controls.lens.model, CocModel::FocalRange);
    const LensSettings wide = lensFor(controls, 2.0);
    EXPECT_NEAR(wide.nearLimitM, 1.0 / 1.25, 1e-12);
    EXPECT_NEAR(wide.farLimitM, 6.0 * 1.25, 1e-12);
    for (int i = 0; i < 12; ++i)
        applyKey(controls, 'l', 2.0);
    // Narrowed past the focus: validate() clamps the limits just around it, with a warning.
    const LensSettings narrow = lensFor(controls, 2.0);
    EXPECT_LT(narrow.nearLimitM, 2.0);
    EXPECT_GT(narrow.farLimitM, 2.0);
    EXPECT_GT(narrow.nearLimitM, 1.9);
    EXPECT_LT(narrow.farLimitM, 2.1);
    EXPECT_FALSE(applyKey(controls, 'l', 2.0).issues.empty());
    // The range follows the focus in proportion.
    const LensSettings far = lensFor(controls, 4.0);
    EXPECT_NEAR(far.nearLimitM / 4.0, narrow.nearLimitM / 2.0, 1e-9);
    applyKey(controls, 'm', 2.0);
    EXPECT_EQ(controls.lens.model, CocModel::ThinLens);
}

TEST(DisplayControls, TogglesQuitAndUnknownKeys)
{
    LiveControls controls;
    const auto before = controls.revision;
    EXPECT_FALSE(applyKey(controls, 'x', 2.0).handled);
    EXPECT_EQ(controls.revision, before);
    applyKey(controls, 'f', 2.0);
    EXPECT_FALSE(controls.autofocus);
    applyKey(controls, 't', 2.0);
    EXPECT_TRUE(controls.tileMap);
    applyKey(controls, ' ', 2.0);
    EXPECT_TRUE(controls.paused);
    applyKey(controls, 'c', 2.0);
    EXPECT_TRUE(controls.recentre);
    EXPECT_GT(controls.revision, before);
    EXPECT_FALSE(controls.quit);
    applyKey(controls, 27, 2.0);
    EXPECT_TRUE(controls.quit);
    controls.quit = false;
    applyKey(controls, 'q', 2.0);
    EXPECT_TRUE(controls.quit);
}

TEST(DisplayControls, FocusCloserThanTheFocalLengthIsClampedForTheFrame)
{
    LiveControls controls;
    std::vector<SettingIssue> issues;
    const LensSettings lens = lensFor(controls, 0.01, &issues); // 1 cm < 50 mm
    EXPECT_GT(lens.focusM, 0.05);
    ASSERT_EQ(issues.size(), 1u);
    EXPECT_EQ(issues[0].parameter, "--focus");
}

cv::Mat gradient(cv::Size size)
{
    cv::Mat image(size, CV_8UC3);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x)
            image.at<cv::Vec3b>(y, x) = {static_cast<uchar>(x % 256), static_cast<uchar>(y % 256), 90};
    return image;
}

TEST(DisplayHud, FrameIsShownAsItIsWithTheHudBandBelow)
{
    const cv::Mat frame = gradient({640, 480});
    HudStatus status;
    const cv::Mat shown = composeHud(frame, status);
    ASSERT_EQ(shown.size(), cv::Size(640, 480 + kHudHeight));
    // Only the focus-window marks (the centre 10 %, 64 x 48 px, and 2 px around) touch the frame.
    cv::Mat diff;
    cv::absdiff(shown(cv::Rect(0, 0, 640, 480)), frame, diff);
    cv::Mat changed;
    cv::cvtColor(diff, changed, cv::COLOR_BGR2GRAY);
    const cv::Rect touched = cv::boundingRect(changed);
    EXPECT_TRUE((touched & cv::Rect(320 - 36, 240 - 28, 72, 56)) == touched) << touched;
    EXPECT_GT(cv::countNonZero(diff.reshape(1)), 0);
    // The band holds text: light pixels on the dark background.
    cv::Mat band;
    cv::cvtColor(shown(cv::Rect(0, 480, 640, kHudHeight)), band, cv::COLOR_BGR2GRAY);
    const double light = cv::countNonZero(band > 150) / static_cast<double>(band.total());
    EXPECT_GT(light, 0.02);
    EXPECT_LT(light, 0.4);
}

TEST(DisplayHud, BandFollowsTheStatus)
{
    const cv::Mat frame = gradient({320, 240});
    HudStatus a;
    HudStatus b = a;
    b.view = View::Coc;
    b.focusM = 3.25;
    b.message = "clamped: --f-number must be between 0.7 and 64, not 71.8";
    b.warning = true;
    const cv::Mat shownA = composeHud(frame, a), shownB = composeHud(frame, b);
    // Narrow frames are padded so the HUD fits.
    ASSERT_EQ(shownA.size(), cv::Size(560, 240 + kHudHeight));
    cv::Mat diff;
    cv::absdiff(shownA(cv::Rect(0, 240, 560, kHudHeight)), shownB(cv::Rect(0, 240, 560, kHudHeight)), diff);
    EXPECT_GT(cv::countNonZero(diff.reshape(1)), 100);
}

TEST(DisplayHud, TileMapOutlinesOnlyTheTilesThatNeedBlur)
{
    const cv::Mat frame(64, 64, CV_8UC3, cv::Scalar(40, 40, 40));
    SceneAnalysis analysis;
    analysis.tiles = {4, 4};
    analysis.tileMinCoc = cv::Mat(4, 4, CV_32F, cv::Scalar(0.0f));
    analysis.tileMaxCoc = cv::Mat(4, 4, CV_32F, cv::Scalar(0.0f));
    analysis.tileMaxCoc.at<float>(0, 0) = 3.0f;  // tile (0, 0) is blurred
    analysis.tileMinCoc.at<float>(3, 3) = -2.0f; // so is tile (3, 3), in front of the focus
    HudStatus status;
    status.focusWindow.centre = {0.5, 0.5};
    const cv::Mat shown = composeHud(frame, status, &analysis);
    const auto at = [&](int x, int y) { return shown.at<cv::Vec3b>(y, x); };
    const cv::Vec3b grey(40, 40, 40);
    EXPECT_NE(at(0, 8), grey);   // left edge of tile (0, 0)
    EXPECT_NE(at(63, 56), grey); // right edge of tile (3, 3)
    EXPECT_EQ(at(8, 8), grey);   // inside tile (0, 0)
    EXPECT_EQ(at(48, 8), grey);  // edge of tile (3, 0): in focus
    EXPECT_EQ(at(16, 56), grey); // edge of tile (1, 3): in focus
}

} // namespace
} // namespace defocus
