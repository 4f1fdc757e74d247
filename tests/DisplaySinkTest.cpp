// SPDX-License-Identifier: LGPL-2.1-or-later
// The display sink's drawing without a window: the picture the window would show (the frame,
// untouched but for the marks and outlines it is given, and the HUD band below it).
// What the keys do is tested in PreviewControllerTest.cpp; the window itself under Xvfb by
// scripts/display-test.sh (CTest label "display").
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "sinks/DisplaySink.hpp"

namespace defocus {
namespace {

cv::Mat gradient(cv::Size size)
{
    cv::Mat image(size, CV_8UC3);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x)
            image.at<cv::Vec3b>(y, x) = {static_cast<uchar>(x % 256), static_cast<uchar>(y % 256), 90};
    return image;
}

Hud someLines()
{
    Hud hud;
    hud.lines = {"focus 2.00 m [auto]   f/2.0  50 mm  max CoC 32.0 px  thin-lens",
                 "view 5 composite   0.0 fps   latency 0 ms   dropped 0   frame 0",
                 "ms: total 0.0  prep 0.0  analysis 0.0  upload 0.0  render 0.0  readback 0.0",
                 "gpu ms/pass:  n/a"};
    hud.note = "keys: 1-7 view  +/- f-number  [ ] max CoC  j/l range  f autofocus  t tiles  spc pause  s shot  q quit";
    return hud;
}

// Defects: marks drawn elsewhere than the region they are given, the frame scaled or recoloured,
// or a band without its text.
TEST(DisplayHud, FrameIsShownAsItIsWithTheHudBandBelow)
{
    const cv::Mat frame = gradient({640, 480});
    const cv::Mat shown = composeHud(frame, someLines());
    ASSERT_EQ(shown.size(), cv::Size(640, 480 + kHudHeight));
    // Only the marks (the centre 10 %, 64 x 48 px, and 2 px around) touch the frame.
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

// Defects: a band that ignores the lines or the note it is handed, or draws a warning like any note.
TEST(DisplayHud, BandShowsTheLinesAndTheNoteItIsGiven)
{
    const cv::Mat frame = gradient({320, 240});
    const Hud a = someLines();
    Hud b = a;
    b.lines[1] = "view 7 coc   0.0 fps   latency 0 ms   dropped 0   frame 0";
    Hud warned = a;
    warned.note = "clamped: --f-number must be between 0.7 and 64, not 71.8";
    warned.warning = true;
    const cv::Mat shownA = composeHud(frame, a), shownB = composeHud(frame, b), shownW = composeHud(frame, warned);
    // Narrow frames are padded so the HUD fits.
    ASSERT_EQ(shownA.size(), cv::Size(560, 240 + kHudHeight));
    const cv::Rect band(0, 240, 560, kHudHeight);
    cv::Mat diff;
    cv::absdiff(shownA(band), shownB(band), diff);
    EXPECT_GT(cv::countNonZero(diff.reshape(1)), 100);
    // The warning is orange (BGR: red above blue); the other lines are grey to white.
    cv::Mat channels[3];
    cv::split(shownW(band), channels);
    EXPECT_GT(cv::countNonZero(channels[2] > channels[0] + 100), 50);
    cv::split(shownA(band), channels);
    EXPECT_EQ(cv::countNonZero(channels[2] > channels[0] + 100), 0);
}

// Defects: outlines not drawn, drawn filled, or drawn past the frame into the band.
TEST(DisplayHud, OutlinesAreDrawnWhereGivenAndClippedToTheFrame)
{
    const cv::Mat frame(64, 64, CV_8UC3, cv::Scalar(40, 40, 40));
    Hud hud;
    hud.marks.centre = {0.5, 0.5};
    hud.outlines = {cv::Rect(0, 0, 16, 16), cv::Rect(48, 48, 32, 32)}; // the second reaches past the frame
    const cv::Mat shown = composeHud(frame, hud);
    const auto at = [&](int x, int y) { return shown.at<cv::Vec3b>(y, x); };
    const cv::Vec3b grey(40, 40, 40);
    EXPECT_NE(at(0, 8), grey);   // left edge of the first
    EXPECT_NE(at(63, 56), grey); // its right edge, clipped to the frame
    EXPECT_NE(at(56, 63), grey); // its bottom edge, clipped to the frame
    EXPECT_EQ(at(8, 8), grey);   // inside the first
    EXPECT_EQ(at(56, 56), grey); // inside the second
    EXPECT_EQ(at(32, 8), grey);  // outside both
}

} // namespace
} // namespace defocus
