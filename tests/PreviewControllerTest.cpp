// SPDX-License-Identifier: LGPL-2.1-or-later
// What defocus-preview's keys and clicks do, without a window: each key's effect on the live
// controls (with clamping through validate()), clicks and a closed window, and the HUD made from
// the status (drawn by sinks/DisplaySink, DisplaySinkTest.cpp).
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "samples/PreviewController.hpp"

namespace defocus {
namespace {

// Defects of applyKey: a key that changes the wrong thing, steps of the wrong size, or an
// impossible value kept without a warning.
TEST(PreviewControls, NumberKeysChooseTheLabViewsThenDepthAndCoc)
{
    LiveControls controls;
    for (int i = 0; i < 7; ++i) {
        const auto outcome = applyKey(controls, '1' + i, 2.0);
        EXPECT_TRUE(outcome.handled);
        EXPECT_EQ(controls.view, kViews[i]);
    }
    EXPECT_EQ(controls.view, Settings::View::Coc);
}

TEST(PreviewControls, FNumberMovesByThirdStopsOnTheStandardScale)
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

TEST(PreviewControls, ImpossibleFNumbersAreClampedWithAWarning)
{
    LiveControls controls;
    controls.lens.fNumber = 64.0;
    auto outcome = applyKey(controls, '+', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.fNumber, 64.0);
    ASSERT_EQ(outcome.issues.size(), 1u);
    EXPECT_EQ(outcome.issues[0].rfind("--f-number ", 0), 0u) << outcome.issues[0];
    controls.lens.fNumber = 0.7;
    outcome = applyKey(controls, '-', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.fNumber, 0.7);
    ASSERT_EQ(outcome.issues.size(), 1u);
    // A step inside the range says nothing.
    EXPECT_TRUE(applyKey(controls, '+', 2.0).issues.empty());
}

// Defect: an aperture key that skips a blade count or lands outside 0 and 3..16, a turn of the
// wrong size, an oval that cannot be undone, or a change the picture does not redraw for.
TEST(PreviewControls, BRAndOChangeTheAperture)
{
    LiveControls controls; // 6 blades
    std::vector<int> seen;
    for (int i = 0; i < 15; ++i) {
        const auto revision = controls.revision;
        const auto outcome = applyKey(controls, 'b', 2.0);
        EXPECT_TRUE(outcome.handled);
        EXPECT_GT(controls.revision, revision);
        seen.push_back(controls.lens.blades);
    }
    EXPECT_EQ(seen, (std::vector<int>{7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 0, 3, 4, 5, 6}));
    EXPECT_EQ(applyKey(controls, 'b', 2.0).message, "aperture: 7 blades");
    applyKey(controls, 'r', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.bladeRotationDeg, 15.0);
    for (int i = 0; i < 11; ++i)
        applyKey(controls, 'r', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.bladeRotationDeg, 180.0);
    applyKey(controls, 'r', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.bladeRotationDeg, -165.0); // stays in [-180, 180]
    EXPECT_EQ(applyKey(controls, 'o', 2.0).message, "aperture: 7 blades -165 deg, ratio 2");
    EXPECT_DOUBLE_EQ(controls.lens.apertureRatio, 2.0);
    applyKey(controls, 'o', 2.0);
    EXPECT_DOUBLE_EQ(controls.lens.apertureRatio, 1.0);
    Settings settings;
    settings.lens = controls.lens;
    EXPECT_TRUE(check(settings).empty());
}

TEST(PreviewControls, BracketsChangeMaxCocAndClampAtZero)
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
    EXPECT_EQ(outcome.issues[0].rfind("--max-coc ", 0), 0u) << outcome.issues[0];
}

TEST(PreviewControls, JWidensAndLNarrowsTheFocalRangeWhichStaysAroundTheFocus)
{
    LiveControls controls;
    EXPECT_EQ(controls.lens.cocModel, Lens::Model::ThinLens);
    applyKey(controls, 'j', 2.0);
    EXPECT_EQ(controls.lens.cocModel, Lens::Model::FocalRange);
    const Lens wide = lensFor(controls, 2.0);
    EXPECT_NEAR(wide.nearM, 1.0 / 1.25, 1e-12);
    EXPECT_NEAR(wide.farM, 6.0 * 1.25, 1e-12);
    for (int i = 0; i < 12; ++i)
        applyKey(controls, 'l', 2.0);
    // Narrowed past the focus: validate() clamps the limits just around it, with a warning.
    const Lens narrow = lensFor(controls, 2.0);
    EXPECT_LT(narrow.nearM, 2.0);
    EXPECT_GT(narrow.farM, 2.0);
    EXPECT_GT(narrow.nearM, 1.9);
    EXPECT_LT(narrow.farM, 2.1);
    EXPECT_FALSE(applyKey(controls, 'l', 2.0).issues.empty());
    // The range follows the focus in proportion.
    const Lens far = lensFor(controls, 4.0);
    EXPECT_NEAR(far.nearM / 4.0, narrow.nearM / 2.0, 1e-9);
    applyKey(controls, 'm', 2.0);
    EXPECT_EQ(controls.lens.cocModel, Lens::Model::ThinLens);
}

TEST(PreviewControls, TogglesQuitAndUnknownKeys)
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

TEST(PreviewControls, FocusCloserThanTheFocalLengthIsClampedForTheFrame)
{
    LiveControls controls;
    std::vector<std::string> issues;
    const Lens lens = lensFor(controls, 0.01, &issues); // 1 cm < 50 mm
    EXPECT_GT(lens.focusM, 0.05);
    ASSERT_EQ(issues.size(), 1u);
    EXPECT_EQ(issues[0].rfind("--focus ", 0), 0u) << issues[0];
}

WindowEvent key(int k)
{
    WindowEvent event;
    event.key = k;
    return event;
}

// Defects: a click that does not reach the autofocus (or reaches it as a recentre), a closed
// window that does not quit, keys served by the window but not applied.
TEST(PreviewController, ClicksFocusKeysApplyAndAClosedWindowQuits)
{
    LiveControls controls;
    PreviewController controller(controls);
    WindowEvent left;
    left.kind = WindowEvent::Kind::LeftClick;
    left.pixel = {63, 47};
    left.point = {0.1, 0.2};
    controller.handle(left, nullptr);
    ASSERT_TRUE(controls.tap.has_value());
    EXPECT_EQ(*controls.tap, cv::Point2d(0.1, 0.2));
    EXPECT_FALSE(controls.recentre);
    const auto afterTap = controls.revision;
    EXPECT_GT(afterTap, 0u);

    WindowEvent right = left;
    right.kind = WindowEvent::Kind::RightClick;
    controller.handle(right, nullptr);
    EXPECT_TRUE(controls.recentre);
    EXPECT_GT(controls.revision, afterTap);

    controller.handle(key('7'), nullptr);
    EXPECT_EQ(controls.view, Settings::View::Coc);
    controller.handle(key('s'), nullptr); // no window: nothing to save, nothing changes
    EXPECT_EQ(controls.view, Settings::View::Coc);
    EXPECT_FALSE(controls.quit);
    WindowEvent closed;
    closed.kind = WindowEvent::Kind::Closed;
    controller.handle(closed, nullptr);
    EXPECT_TRUE(controls.quit);
}

// Defect: keys judged at another focus than the one the loop renders with (a clamp missed or
// made up).
TEST(PreviewController, KeysAreJudgedAtTheFocusInUse)
{
    LiveControls controls;
    PreviewController controller(controls);
    const HudStatus status;
    controller.handle(key('+'), nullptr); // at 2 m (before the loop sets a focus): nothing to clamp
    EXPECT_FALSE(controller.hud(status).warning);
    controller.setFocusForKeys(0.01); // closer than the 50 mm focal length
    controller.handle(key('+'), nullptr);
    const Hud hud = controller.hud(status);
    EXPECT_TRUE(hud.warning);
    EXPECT_NE(hud.note.find("--focus"), std::string::npos) << hud.note;
}

// Defects: the HUD missing the key's effect, keeping it over the frame's own warning, or showing
// a warning in the colour of a note.
TEST(PreviewHud, LastEffectIsShownUnlessTheFrameHasAWarning)
{
    LiveControls controls;
    PreviewController controller(controls);
    HudStatus status;
    EXPECT_EQ(controller.hud(status).note.rfind("keys:", 0), 0u);
    controller.handle(key('t'), nullptr);
    EXPECT_EQ(controller.hud(status).note, "tile map on (outlined tiles are blurred)");
    EXPECT_FALSE(controller.hud(status).warning);
    status.message = "clamped: --focus must be at least 0.05 m";
    status.warning = true;
    const Hud warned = controller.hud(status);
    EXPECT_EQ(warned.note, status.message);
    EXPECT_TRUE(warned.warning);
}

// Defect: HUD lines that do not follow the status (the view, the focus, the model).
TEST(PreviewHud, LinesFollowTheStatus)
{
    HudStatus a;
    HudStatus b = a;
    b.view = Settings::View::Coc;
    b.focusM = 3.25;
    b.targetM = 3.25;
    b.autofocus = false;
    const Hud hudA = hudFor(a), hudB = hudFor(b);
    ASSERT_EQ(hudA.lines.size(), 4u);
    EXPECT_EQ(hudA.lines[0].rfind("focus 2.00 m [auto]", 0), 0u) << hudA.lines[0];
    EXPECT_EQ(hudB.lines[0].rfind("focus 3.25 m [manual]", 0), 0u) << hudB.lines[0];
    EXPECT_EQ(hudA.lines[1].rfind("view 5 composite", 0), 0u) << hudA.lines[1];
    EXPECT_EQ(hudB.lines[1].rfind("view 7 coc", 0), 0u) << hudB.lines[1];
    EXPECT_TRUE(hudA.marks.active);
    EXPECT_FALSE(hudB.marks.active);
}

cv::Mat grey64()
{
    return cv::Mat(64, 64, CV_8UC3, cv::Scalar(40, 40, 40));
}

// Defect: outlines for tiles in focus, or none for a tile behind or in front of the focus.
TEST(PreviewHud, TileMapOutlinesOnlyTheTilesThatNeedBlur)
{
    const cv::Mat frame = grey64();
    Plan plan;
    plan.tileSizePx = 16;
    plan.tileMap = cv::Mat(4, 4, CV_8UC1, cv::Scalar(0));
    plan.tileMap.at<std::uint8_t>(0, 0) = 1; // tile (0, 0) is blurred
    plan.tileMap.at<std::uint8_t>(3, 3) = 1; // so is tile (3, 3), in front of the focus
    HudStatus status;
    status.focusWindow.centre = {0.5, 0.5};
    const cv::Mat shown = composeHud(frame, hudFor(status, &plan));
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
