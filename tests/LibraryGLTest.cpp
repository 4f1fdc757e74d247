// SPDX-License-Identifier: LGPL-2.1-or-later
// libdefocus' public API (include/defocus/): its errors speak the command line's words, the
// command line's automatic focus, the live autofocus, a Filter that follows the calling thread, and
// what the defocus program takes from it: the contact sheet, the last frame's GPU times, the
// renderer and the device, and a preset resolved.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <set>
#include <thread>

#include <sys/inotify.h>
#include <unistd.h>

#include <defocus/defocus.hpp>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/ImageCompare.hpp"
#include "tests/YuvPlanes.hpp"
#include "tests/TestSupport.hpp"

namespace {

namespace fs = std::filesystem;

struct Pair {
    fs::path color, depth;
};

/// Line `line` of the bundled clip's associations.
Pair bundled(int line)
{
    std::ifstream list(defocus::test::dataDir() / "tum_fr1_rpy" / "associations.txt");
    std::string text;
    for (int i = 0; i < line; ++i)
        std::getline(list, text);
    std::istringstream fields(text);
    std::string t1, rgb, t2, depth;
    fields >> t1 >> rgb >> t2 >> depth;
    const fs::path dir = defocus::test::dataDir() / "tum_fr1_rpy";
    return {dir / rgb, dir / depth};
}

using defocus::test::identical;

/// The bundled clip's lens (focus 1 m, f/1.4, 5000 units per metre) with `preset` and `kernel`:
/// the settings the tests that go over every preset and both kernels filter with.
defocus::Settings presetSettings(defocus::Quality::Preset preset, defocus::Quality::Hexagon kernel)
{
    defocus::Settings settings;
    settings.depthScale = 5000;
    settings.lens.focusM = 1.0;
    settings.lens.fNumber = 1.4;
    settings.quality.preset = preset;
    settings.quality.hexagon = kernel;
    return settings;
}
using defocus::test::layoutName;
using defocus::test::opencvToBgr;
using defocus::test::opencvYuv;
using defocus::test::packedPlanes;

class Library : public ::testing::Test {
protected:
    void SetUp() override
    {
        const Pair pair = bundled(9);
        color_ = cv::imread(pair.color.string(), cv::IMREAD_COLOR);
        depth_ = cv::imread(pair.depth.string(), cv::IMREAD_UNCHANGED);
        settings_.depthScale = 5000;
        settings_.lens.focusM = 1.0;
        settings_.lens.fNumber = 1.4;
        try {
            filter_.emplace(settings_);
        } catch (const defocus::GlError& error) {
            GTEST_SKIP() << "no OpenGL 4.5: " << error.what();
        }
    }
    cv::Mat color_, depth_;
    defocus::Settings settings_;
    std::optional<defocus::Filter> filter_;
};

// Defect caught: settings out of range accepted, or refused with another message than the
// command line's (the element and the programs show these words to users).
TEST_F(Library, SettingsErrorsSpeakTheCommandLinesWords)
{
    defocus::Settings bad = settings_;
    bad.lens.fNumber = 0.5;
    try {
        filter_->setSettings(bad);
        FAIL() << "f/0.5 accepted";
    } catch (const defocus::SettingsError& error) {
        EXPECT_STREQ(error.what(), "--f-number must be between 0.7 and 64, not 0.5");
    }
    EXPECT_EQ(filter_->settings().lens.fNumber, 1.4) << "a refused change must leave the settings as they were";
    bad = settings_;
    bad.quality.samples = 1;
    EXPECT_THROW(filter_->setSettings(bad), defocus::SettingsError);

    defocus::Settings clamped = bad;
    clamped.lens.focusM = 0.01;
    const auto issues = defocus::check(clamped, true);
    ASSERT_EQ(issues.size(), 2u);
    EXPECT_EQ(issues[0], "--focus 0.01 m must be farther than the focal length (0.05 m)");
    EXPECT_EQ(issues[1], "--samples must be between 2 and 64, not 1");
    EXPECT_EQ(*clamped.quality.samples, 2);
    EXPECT_GT(clamped.lens.focusM, 0.05);
    EXPECT_TRUE(defocus::check(clamped).empty()) << "clamped settings are valid";
}

// Defect caught: images of the wrong type or shape filtered anyway (garbage, or an OpenCV
// assertion) instead of an InputError that says what was expected.
TEST_F(Library, InputErrorsNameTheImage)
{
    cv::Mat color16;
    color_.convertTo(color16, CV_16UC3);
    try {
        filter_->process(color16, depth_);
        FAIL() << "16-bit colour accepted";
    } catch (const defocus::InputError& error) {
        EXPECT_NE(std::string(error.what()).find("colour image is 16-bit, 3 channels"), std::string::npos)
            << error.what();
    }
    EXPECT_THROW(filter_->process(color_, cv::Mat(480, 480, CV_16UC1, cv::Scalar(5000))), defocus::InputError);
    EXPECT_THROW(filter_->process(color_, cv::Mat(480, 640, CV_8UC1, cv::Scalar(50))), defocus::InputError);
    // Half-size depth of the same aspect is resized, as the command line does.
    cv::Mat half;
    cv::resize(depth_, half, {320, 240}, 0, 0, cv::INTER_NEAREST);
    EXPECT_NO_THROW(filter_->process(color_, half));
}

// Defect caught: a view into a larger image (rows with gaps between them) refused with a raw
// OpenCV assertion (isContinuous), or read as if its rows were packed (a sheared frame).
TEST_F(Library, SubImagesAreFilteredAsTheirCopies)
{
    const cv::Rect rect(64, 48, 480, 360); // the frame's aspect ratio, away from every edge
    const cv::Mat colorView = color_(rect), depthView = depth_(rect);
    ASSERT_FALSE(colorView.isContinuous());
    ASSERT_FALSE(depthView.isContinuous());
    const cv::Mat copied = filter_->process(colorView.clone(), depthView.clone());
    filter_->reset();
    cv::Mat viewed;
    ASSERT_NO_THROW(viewed = filter_->process(colorView, depthView));
    EXPECT_TRUE(identical(viewed, copied)) << "16-bit depth";

    cv::Mat metres;
    depth_.convertTo(metres, CV_32F, 1.0 / settings_.depthScale);
    cv::Mat bgra;
    cv::cvtColor(color_, bgra, cv::COLOR_BGR2BGRA);
    filter_->reset();
    ASSERT_NO_THROW(viewed = filter_->process(colorView, metres(rect)));
    EXPECT_TRUE(identical(viewed, copied)) << "float depth";
    filter_->reset();
    ASSERT_NO_THROW(viewed = filter_->process(bgra(rect), depthView));
    EXPECT_TRUE(identical(viewed, copied)) << "BGRA colour";
}

// Defect caught: FirstFrame measuring focus otherwise than `defocus --focus auto` (another
// window, a mean instead of the median, measured again on later frames): the results differ.
TEST_F(Library, FirstFrameAutofocusIsTheCommandLinesAuto)
{
    const Pair pair = bundled(9);
    const fs::path out = defocus::test::scratchDir("library_auto") / "cli.png";
    const std::string command = std::string(DEFOCUS_BINARY_DIR) + "/defocus '" + pair.color.string() + "' --depth '" +
                                pair.depth.string() + "' --depth-scale 5000 --f-number 1.4 --focus auto -q -o '" +
                                out.string() + "' > /dev/null";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    defocus::Settings automatic = settings_;
    automatic.autofocus.mode = defocus::AutofocusOptions::Mode::FirstFrame;
    filter_->setSettings(automatic);
    EXPECT_TRUE(identical(filter_->process(color_, depth_), cv::imread(out.string(), cv::IMREAD_COLOR)));
    const double chosen = filter_->lastFrame().focusM;
    // Later frames keep the first frame's focus, whatever their depth.
    filter_->process(color_, cv::Mat(depth_.size(), CV_16UC1, cv::Scalar(20000)));
    EXPECT_EQ(filter_->lastFrame().focusM, chosen);
    filter_->reset();
    filter_->process(color_, cv::Mat(depth_.size(), CV_16UC1, cv::Scalar(20000)));
    EXPECT_NEAR(filter_->lastFrame().focusM, 4.0, 1e-6) << "reset() measures afresh";
}

// Defect caught: Follow not stepped by the frames' timestamps (no convergence, or a jump when
// the time constant asks for a glide).
TEST_F(Library, FollowGlidesToTheDepthOfTheCentre)
{
    defocus::Settings follow = settings_;
    follow.autofocus.mode = defocus::AutofocusOptions::Mode::Follow;
    follow.autofocus.timeConstantS = 0.25;
    filter_->setSettings(follow);
    const cv::Mat near(depth_.size(), CV_16UC1, cv::Scalar(5000)), far(depth_.size(), CV_16UC1, cv::Scalar(15000));
    filter_->process(color_, near, 1.0);
    EXPECT_NEAR(filter_->lastFrame().focusM, 1.0, 1e-6) << "the first measurement is taken at once";
    filter_->process(color_, far, 1.0 + 1.0 / 30);
    const double after = filter_->lastFrame().focusM;
    EXPECT_GT(after, 1.0);
    EXPECT_LT(after, 1.5) << "one frame of a 0.25 s spring moves a little of the way";
    for (int i = 2; i < 120; ++i)
        filter_->process(color_, far, 1.0 + i / 30.0);
    EXPECT_NEAR(filter_->lastFrame().focusM, 3.0, 0.01) << "4 s = 16 time constants: there";
}

// Defect caught: a Filter that only works on the thread that made it (its context left current
// there, or not made current on the caller): the second thread's frame came back black, without
// an error, unless the first thread had called release().
TEST_F(Library, FollowsTheCallingThread)
{
    const cv::Mat here = filter_->process(color_, depth_);
    cv::Mat there;
    std::string error;
    std::thread other([&] {
        try {
            there = filter_->process(color_, depth_);
        } catch (const std::exception& e) {
            error = e.what();
        }
    });
    other.join();
    ASSERT_EQ(error, "");
    EXPECT_TRUE(identical(here, there));
    EXPECT_TRUE(identical(filter_->process(color_, depth_), here)) << "and back on this thread";
}

// Defect caught: release() that breaks the handover (it is what code written for the older
// Filter calls before handing it on).
TEST_F(Library, HandedToAnotherThreadAfterRelease)
{
    const cv::Mat here = filter_->process(color_, depth_);
    filter_->release();
    cv::Mat there;
    std::string error;
    std::thread other([&] {
        try {
            there = filter_->process(color_, depth_);
            filter_->release();
        } catch (const std::exception& e) {
            error = e.what();
        }
    });
    other.join();
    ASSERT_EQ(error, "");
    EXPECT_TRUE(identical(here, there));
}

// Defect caught: contactSheet() that leaves the Filter in another state than a plain frame would
// (the frame counter advanced, the timings or the next frame's result those of the views' reads),
// or a sheet that lacks views.
TEST_F(Library, ContactSheetLeavesTheFrameAsItWas)
{
    const Pair next = bundled(10);
    const cv::Mat nextColor = cv::imread(next.color.string(), cv::IMREAD_COLOR);
    const cv::Mat nextDepth = cv::imread(next.depth.string(), cv::IMREAD_UNCHANGED);
    EXPECT_THROW(filter_->contactSheet(), defocus::InputError) << "no frame yet";
    filter_->process(color_, depth_);
    const cv::Mat sheet = filter_->contactSheet();
    EXPECT_EQ(filter_->lastFrame().index, 0u);
    EXPECT_FALSE(filter_->lastFrame().plan.allInFocus);
    ASSERT_EQ(sheet.type(), CV_8UC3);
    // 7 views and the plan, four to a row, each at least the frame's size.
    EXPECT_GE(sheet.cols, 4 * color_.cols);
    EXPECT_GE(sheet.rows, 2 * color_.rows);
    const cv::Mat afterSheet = filter_->process(nextColor, nextDepth);
    EXPECT_EQ(filter_->lastFrame().index, 1u);

    defocus::Filter plain(settings_);
    plain.process(color_, depth_);
    EXPECT_TRUE(identical(plain.process(nextColor, nextDepth), afterSheet));
}

// Defects caught: an image the caller still holds filled again with a later frame (its memory
// reused without asking whether anyone else holds it); an image let go of not reused, each
// frame a new allocation whose pages the copy faults in.
TEST_F(Library, ImagesStayAsReturnedWhileHeldAndAreFilledAgainOnceLetGo)
{
    const cv::Mat first = filter_->process(color_, depth_);
    ASSERT_FALSE(filter_->lastFrame().plan.allInFocus);
    const cv::Mat firstAsReturned = first.clone();
    defocus::Settings farther = settings_;
    farther.lens.focusM = 2.0;
    filter_->setSettings(farther);
    cv::Mat second = filter_->process(color_, depth_);
    ASSERT_FALSE(filter_->lastFrame().plan.allInFocus);
    EXPECT_TRUE(identical(first, firstAsReturned)) << "the first image changed under its holder";
    EXPECT_FALSE(identical(first, second));
    EXPECT_NE(first.data, second.data);

    const cv::Mat secondAsReturned = second.clone();
    const unsigned char* secondMemory = second.data;
    second.release();
    const cv::Mat third = filter_->process(color_, depth_);
    EXPECT_EQ(third.data, secondMemory) << "the memory let go of was not filled again";
    EXPECT_TRUE(identical(third, secondAsReturned));
    EXPECT_TRUE(identical(first, firstAsReturned));

    // A frame all in focus is returned from the same images, as it came in.
    filter_->setSettings(settings_);
    const cv::Mat flat(depth_.size(), CV_32F, cv::Scalar(1.0f));
    const cv::Mat inFocus = filter_->process(color_, flat);
    ASSERT_TRUE(filter_->lastFrame().plan.allInFocus);
    EXPECT_TRUE(identical(inFocus, color_));
    EXPECT_NE(inFocus.data, color_.data) << "the caller's own image returned";
    EXPECT_TRUE(identical(first, firstAsReturned));
    EXPECT_TRUE(identical(third, secondAsReturned));
}

// Defect caught: the last frame's GPU times lost at the end of a stream (finishGpuTimings() not
// waiting for them), or put to another frame than the one they measured.
TEST_F(Library, LastFramesGpuTimesAtTheEnd)
{
    if (!filter_->rendererInfo().timerQueries)
        GTEST_SKIP() << "this driver has no GPU timer queries";
    filter_->process(color_, depth_);
    EXPECT_TRUE(filter_->lastFrame().timings.gpu.empty()) << "read one frame late";
    filter_->process(color_, depth_);
    EXPECT_FALSE(filter_->lastFrame().timings.gpu.empty());
    EXPECT_EQ(filter_->lastFrame().timings.gpuFrame, 0u);
    const auto last = filter_->finishGpuTimings();
    ASSERT_FALSE(last.empty()) << "frame 1's passes";
    for (const auto& pass : last) {
        EXPECT_FALSE(pass.name.empty());
        EXPECT_GE(pass.ms, 0.0) << pass.name;
    }
}

// An all-in-focus frame's report accounts for the whole of process(). Defect caught: the report
// asking the pipeline for the depth's share of holes, which filled them, uploaded and analysed
// the frame again after the frame's clock had stopped (the work done twice; at 1080p on llvmpipe
// 59-95 ms of wall time against a reported total of 6-15 ms).
TEST_F(Library, AFrameInFocusReportsTheWholeFrame)
{
    // 1280x960: hole filling, upload and analysis take milliseconds here, yet the test is quick.
    cv::Mat color, depth16, metres;
    cv::resize(color_, color, {1280, 960});
    cv::resize(depth_, depth16, color.size(), 0, 0, cv::INTER_NEAREST);
    depth16.convertTo(metres, CV_32F, 1.0 / settings_.depthScale);
    // What that work costs on this machine now: the same frame, blurred, times it.
    double rerunMs = 1e9;
    for (int i = 0; i < 3; ++i) {
        filter_->process(color, metres);
        ASSERT_FALSE(filter_->lastFrame().plan.allInFocus);
        const defocus::Timings& t = filter_->lastFrame().timings;
        rerunMs = std::min(rerunMs, t.depthPrepMs + t.uploadMs + t.analysisMs);
    }
    // All in focus: every measured depth on the focus plane, the Kinect's holes kept.
    cv::Mat flat(metres.size(), CV_32F, cv::Scalar(0.0f));
    flat.setTo(settings_.lens.focusM, metres > 0.0f);
    const double holes = static_cast<double>(flat.total() - static_cast<std::size_t>(cv::countNonZero(flat))) /
                         static_cast<double>(flat.total());
    ASSERT_GT(holes, 0.0);
    // The least of five frames' time outside the report: a frame slowed by the scheduler
    // does not decide. Half the measured rerun: the defect adds all of it.
    double outsideMs = 1e9;
    for (int i = 0; i < 5; ++i) {
        const auto start = std::chrono::steady_clock::now();
        filter_->process(color, flat);
        const double wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        const defocus::FrameReport& r = filter_->lastFrame();
        ASSERT_TRUE(r.plan.allInFocus);
        EXPECT_DOUBLE_EQ(r.plan.invalidDepthFraction, holes);
        outsideMs = std::min(outsideMs, wallMs - r.timings.totalMs);
    }
    EXPECT_LT(outsideMs, 0.5 * rerunMs) << "of process()'s wall time, " << outsideMs
                                       << " ms is not in the report; hole filling, upload and analysis take "
                                       << rerunMs << " ms";
}

// Defect caught: rendererInfo()/probeRenderer() describing another context than the one the
// filter renders in, or an EGL device that does not exist quietly replaced by another (the
// command line's --egl-device promises only that one).
TEST_F(Library, RendererAndDevice)
{
    const defocus::RendererInfo info = filter_->rendererInfo();
    EXPECT_EQ(info.glRenderer, filter_->renderer());
    EXPECT_FALSE(info.platform.empty());
    EXPECT_NE(info.glVersion.find("4."), std::string::npos) << info.glVersion;
    const defocus::RendererInfo probed = defocus::probeRenderer();
    EXPECT_EQ(probed.glRenderer, info.glRenderer);
    EXPECT_EQ(probed.eglDevice, info.eglDevice);
    const int none = static_cast<int>(defocus::eglDevices().size()) + 7;
    EXPECT_THROW(defocus::Filter(settings_, defocus::ContextOptions{none}), defocus::GlError);
    EXPECT_THROW(defocus::probeRenderer(defocus::ContextOptions{none}), defocus::GlError);
}

// Defect caught: resolve() leaving fields empty (a report that says null where the filter ran
// the preset's value), or overriding a field the caller set; or filling the precision, which
// the presets leave to the renderer (half floats on a GPU, full on llvmpipe).
TEST(LibrarySettings, ResolveFillsThePresetsValues)
{
    defocus::Quality high;
    high.preset = defocus::Quality::Preset::High;
    const defocus::Quality resolved = defocus::resolve(high);
    EXPECT_EQ(resolved.samples, 12);
    EXPECT_EQ(resolved.resolution, defocus::Quality::Resolution::Full);
    EXPECT_EQ(resolved.hexagon, defocus::Quality::Hexagon::Rhombi);
    EXPECT_FALSE(resolved.precision.has_value());
    EXPECT_EQ(resolved.nearField, true);
    defocus::Quality fast;
    fast.preset = defocus::Quality::Preset::Fast;
    fast.samples = 9;
    fast.nearField = false;
    fast.precision = defocus::Quality::Precision::F16;
    const defocus::Quality mixed = defocus::resolve(fast);
    EXPECT_EQ(mixed.precision, defocus::Quality::Precision::F16);
    EXPECT_EQ(mixed.samples, 9);
    EXPECT_EQ(mixed.nearField, false);
    EXPECT_EQ(mixed.resolution, defocus::Quality::Resolution::Half);
}

} // namespace

// Defect caught: the tile map transposed, of the wrong size, or marking tiles that are only
// copied (the preview's tile map would outline the sharp half of the frame).
TEST_F(Library, TileMapMarksTheTilesTheBlurProcesses)
{
    // 100x60: a last column and row cut by the frame's edge. Left of x = 48 on the focus plane,
    // right of it 4 m away at f/1.4: blurred by far more than half a pixel.
    cv::Mat color(60, 100, CV_8UC3, cv::Scalar(90, 120, 150));
    cv::Mat metres(color.size(), CV_32F, cv::Scalar(4.0f));
    metres.colRange(0, 48).setTo(settings_.lens.focusM);
    filter_->process(color, metres);
    const defocus::Plan& plan = filter_->lastFrame().plan;
    ASSERT_EQ(plan.tileSizePx, 16);
    ASSERT_EQ(plan.tileMap.type(), CV_8UC1);
    ASSERT_EQ(plan.tileMap.size(), cv::Size(7, 4));
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 7; ++x) {
            // Tile 2 ends at x = 47; tile 3 starts at 48, the depth edge: blurred from there on.
            const int expected = x >= 3 ? 1 : 0;
            EXPECT_EQ(plan.tileMap.at<std::uint8_t>(y, x), expected) << "tile " << x << "," << y;
        }
    EXPECT_EQ(static_cast<std::size_t>(cv::countNonZero(plan.tileMap)), plan.blurTiles);
}

// Defect caught: a view or preset name that the command line's --view / --quality does not take
// (the preview's HUD and the programs' reports print these words), or two views with one name.
TEST(LibrarySettings, ViewAndQualityNamesAreTheCommandLines)
{
    const char* views[] = {"input", "horizontal", "diagonal-a", "diagonal-b", "composite", "depth", "coc"};
    ASSERT_EQ(std::size(defocus::kViews), std::size(views));
    for (std::size_t i = 0; i < std::size(views); ++i) {
        EXPECT_EQ(defocus::viewName(defocus::kViews[i]), views[i]);
        EXPECT_EQ(defocus::viewNamed(views[i]), defocus::kViews[i]);
    }
    EXPECT_EQ(defocus::viewNamed("Composite"), std::nullopt);
    EXPECT_EQ(defocus::qualityName(defocus::Quality::Preset::Fast), "fast");
    EXPECT_EQ(defocus::qualityName(defocus::Quality::Preset::High), "high");
    EXPECT_EQ(defocus::qualityNamed("balanced"), defocus::Quality::Preset::Balanced);
    EXPECT_EQ(defocus::qualityNamed("best"), std::nullopt);
}

// Defect caught: the public tracker ignoring its options (tap region, time constant), measuring
// the centre after a tap, or the centre median counting holes as depth.
TEST(LibraryFocus, TrackerMeasuresWhereItIsToldAndGlides)
{
    // 2 m everywhere, a 1 m object around (0.8, 0.3); holes (0) across the top rows.
    cv::Mat metres(240, 320, CV_32F, cv::Scalar(2.0f));
    metres(cv::Rect(246, 62, 20, 20)).setTo(1.0f);
    metres.rowRange(0, 10).setTo(0.0f);
    defocus::FocusTrackerOptions options;
    options.timeConstantS = 0.5;
    defocus::FocusTracker tracker(options, 3.0);
    EXPECT_NEAR(tracker.update(metres, 1.0 / 30), 2.0, 1e-6) << "the first measurement is taken at once";
    tracker.tap({256.0 / 320, 72.0 / 240}, 320.0 / 240);
    EXPECT_TRUE(tracker.tapped());
    EXPECT_NEAR(tracker.region().centre.x, 0.8, 1e-9);
    tracker.update(metres, 1.0 / 30);
    EXPECT_NEAR(tracker.targetM(), 1.0, 1e-6);
    EXPECT_GT(tracker.focusM(), 1.5) << "one frame of a 0.5 s spring moves a little way";
    for (int i = 0; i < 105; ++i) // 3.5 s = 7 time constants (99 % of a step takes 6.6): within 1 %
        tracker.advance(1.0 / 30);
    EXPECT_NEAR(1.0 / tracker.focusM(), 1.0, 0.01 * 0.5);
    tracker.recentre();
    EXPECT_FALSE(tracker.tapped());
    EXPECT_TRUE(tracker.retarget(metres));
    EXPECT_NEAR(tracker.targetM(), 2.0, 1e-6);
    tracker.setFocus(std::numeric_limits<double>::infinity());
    EXPECT_TRUE(std::isinf(tracker.focusM()));
    EXPECT_TRUE(tracker.settled());

    EXPECT_NEAR(defocus::medianCentreDepth(metres).value_or(0.0), 2.0, 1e-6);
    EXPECT_EQ(defocus::medianCentreDepth(metres.rowRange(0, 10)), std::nullopt) << "holes only";
    EXPECT_NEAR(defocus::secondsBetweenFrames(10.0, 10.04, 1.0 / 30), 0.04, 1e-12);
    EXPECT_DOUBLE_EQ(defocus::secondsBetweenFrames(0.0, 10.04, 1.0 / 30), 1.0 / 30);
}

// Defect caught: a synthetic Source that renders nothing (no GL context of its own, or its
// context not current where next() is called from), loses its focus pull, or takes the EGL
// display down with it while a Filter still uses it (either may end first).
TEST(LibrarySource, SyntheticSceneRendersInItsOwnContext)
{
    defocus::SourceSettings settings;
    defocus::SyntheticClip clip;
    clip.frames = 3;
    settings.synthetic = clip;
    std::optional<defocus::Source> source;
    try {
        source.emplace(settings);
    } catch (const defocus::GlError& error) {
        GTEST_SKIP() << "no OpenGL 4.5: " << error.what();
    }
    defocus::Filter filter;
    ASSERT_EQ(source->frameCount(), 3u);
    std::optional<defocus::Frame> first = source->next();
    ASSERT_TRUE(first);
    EXPECT_EQ(first->color.type(), CV_32FC3);
    EXPECT_EQ(first->color.size(), cv::Size(640, 480));
    EXPECT_EQ(first->depth.type(), CV_32FC1);
    double lo = 0, hi = 0;
    cv::minMaxLoc(first->depth, &lo, &hi);
    EXPECT_GT(hi, lo) << "a scene with depth, not a cleared target";
    EXPECT_GT(cv::mean(first->color)[1], 0.0);
    // The second frame from another thread, between two filtered frames on this one.
    filter.process(first->color, first->depth);
    std::optional<defocus::Frame> second;
    std::thread([&] { second = source->next(); }).join();
    ASSERT_TRUE(second);
    EXPECT_GT(cv::mean(second->color)[1], 0.0);
    filter.process(second->color, second->depth);
    ASSERT_TRUE(source->sceneFocusM(0) && source->sceneFocusM(2));
    EXPECT_NE(*source->sceneFocusM(0), *source->sceneFocusM(2)) << "the scene pulls its focus";
    source.reset(); // the Source ends first; the Filter goes on
    EXPECT_NO_THROW(filter.process(second->color, second->depth));

    clip.focusPull = false;
    settings.synthetic = clip;
    defocus::Source fixed(settings);
    EXPECT_EQ(fixed.sceneFocusM(0), std::nullopt);
    clip.scene = "teapot";
    settings.synthetic = clip;
    EXPECT_THROW(defocus::Source{settings}, defocus::SettingsError);
}

// Defect caught: frames in flight that come back in another order, with another frame's pixels
// (a readback buffer reused before it was read, a fence not waited for), with another frame's
// report, or different from one frame at a time, on any preset or kernel; a frame all in focus
// (ready at once) overtaking the blurred one before it.
TEST(LibraryInFlight, FramesInFlightAreTheFramesOneAtATime)
{
    std::vector<std::pair<cv::Mat, cv::Mat>> frames;
    for (int line : {4, 5, 6, 7, 8}) {
        const Pair pair = bundled(line);
        frames.emplace_back(cv::imread(pair.color.string(), cv::IMREAD_COLOR),
                            cv::imread(pair.depth.string(), cv::IMREAD_UNCHANGED));
    }
    cv::Mat flat(frames[2].second.size(), CV_32F, cv::Scalar(1.0f)); // frame 2: all in focus at 1 m
    frames[2].second = flat;
    for (const auto preset : {defocus::Quality::Preset::Fast, defocus::Quality::Preset::Balanced,
                              defocus::Quality::Preset::High})
        for (const auto kernel : {defocus::Quality::Hexagon::Rhombi, defocus::Quality::Hexagon::McIntosh}) {
            defocus::Settings settings = presetSettings(preset, kernel);
            const std::string what = std::string(defocus::qualityName(preset)) +
                                     (kernel == defocus::Quality::Hexagon::Rhombi ? ", rhombi" : ", mcintosh");
            std::optional<defocus::Filter> serial, pipelined;
            try {
                serial.emplace(settings);
                pipelined.emplace(settings);
            } catch (const defocus::GlError& error) {
                GTEST_SKIP() << "no OpenGL 4.5: " << error.what();
            }
            std::vector<cv::Mat> expected;
            std::vector<defocus::Plan> plans;
            for (std::size_t i = 0; i < frames.size(); ++i) {
                settings.lens.focusM = 1.0 + 0.25 * static_cast<double>(i % 2) * (i == 2 ? 0 : 1); // frames differ
                serial->setSettings(settings);
                expected.push_back(serial->process(frames[i].first, frames[i].second));
                plans.push_back(serial->lastFrame().plan);
            }
            std::size_t received = 0;
            const auto check = [&](const std::optional<cv::Mat>& image) {
                ASSERT_TRUE(image) << what;
                EXPECT_TRUE(identical(*image, expected[received])) << what << ", frame " << received;
                EXPECT_EQ(pipelined->lastFrame().index, received) << what;
                EXPECT_EQ(pipelined->lastFrame().plan.allInFocus, plans[received].allInFocus) << what;
                EXPECT_EQ(pipelined->lastFrame().plan.blurTiles, plans[received].blurTiles) << what;
                ++received;
            };
            for (std::size_t i = 0; i < frames.size(); ++i) {
                settings.lens.focusM = 1.0 + 0.25 * static_cast<double>(i % 2) * (i == 2 ? 0 : 1);
                pipelined->setSettings(settings);
                pipelined->submit(frames[i].first, frames[i].second);
                if (pipelined->framesInFlight() >= defocus::Filter::kFramesInFlight)
                    check(pipelined->receive());
            }
            EXPECT_THROW(pipelined->process(frames[0].first, frames[0].second), defocus::Error);
            while (pipelined->framesInFlight() > 0)
                check(pipelined->receive());
            EXPECT_EQ(received, frames.size());
            EXPECT_FALSE(pipelined->receive());
        }
}

// Defect caught: BGRx in or BGRA out that is not the BGR frame's result (channels swapped, the
// fourth input byte reaching the picture, an alpha that is not opaque), blurred or all in focus.
TEST_F(Library, BgrxInAndBgraOutAreTheBgrFramesResult)
{
    cv::Mat bgrx;
    cv::cvtColor(color_, bgrx, cv::COLOR_BGR2BGRA);
    cv::Mat noise(color_.size(), CV_8UC1);
    cv::randu(noise, 0, 256);
    const int toX[] = {0, 3};
    cv::mixChannels(&noise, 1, &bgrx, 1, toX, 1); // the x byte is anything
    cv::Mat flat(depth_.size(), CV_16UC1, cv::Scalar(settings_.depthScale * settings_.lens.focusM));
    for (const cv::Mat& depth : {depth_, flat}) {
        const bool inFocus = depth.data == flat.data;
        const cv::Mat expected = filter_->process(color_, depth);
        ASSERT_EQ(filter_->lastFrame().plan.allInFocus, inFocus);
        EXPECT_TRUE(identical(filter_->process(bgrx, depth), expected)) << "BGRx in, BGR out; in focus " << inFocus;
        defocus::Settings bgra = settings_;
        bgra.output = defocus::Settings::Output::Srgb8Bgra;
        filter_->setSettings(bgra);
        for (const cv::Mat& input : {color_, bgrx}) {
            const cv::Mat out = filter_->process(input, depth);
            ASSERT_EQ(out.type(), CV_8UC4);
            cv::Mat bgr, alpha;
            cv::cvtColor(out, bgr, cv::COLOR_BGRA2BGR);
            cv::extractChannel(out, alpha, 3);
            EXPECT_TRUE(identical(bgr, expected)) << input.channels() << " channels in, BGRA out; in focus " << inFocus;
            EXPECT_EQ(cv::countNonZero(alpha != 255), 0) << "alpha not opaque; in focus " << inFocus;
        }
        filter_->setSettings(settings_);
    }
}

namespace {

/// The planes of `yuv` as views into larger images (rows padded, as a GstVideoFrame's may be).
defocus::YuvImage padded(const defocus::YuvImage& yuv)
{
    defocus::YuvImage views = yuv;
    for (cv::Mat* plane : {&views.y, &views.u, &views.v}) {
        if (plane->empty())
            continue;
        cv::Mat wider(plane->rows, plane->cols + 24, plane->type(), cv::Scalar::all(77));
        plane->copyTo(wider.colRange(0, plane->cols));
        *plane = wider.colRange(0, plane->cols);
    }
    return views;
}

} // namespace

// Defects caught: Cb and Cr swapped, a pixel given another block's chroma, the matrix or the range
// of another standard (BT.601 for BT.709, limited for full), a clamp missing (wrapping at 0 or
// 255). OpenCV's conversions are the references: its BT.601 limited range for 4:2:0, its JPEG one
// (BT.601 full range) on the chroma repeated per 2x2 block; BT.709 by its primaries.
TEST(LibraryYuv, ConversionIsOpenCvsAndTheStandardsColours)
{
    const Pair pair = bundled(9);
    const cv::Mat bgr = cv::imread(pair.color.string(), cv::IMREAD_COLOR);
    for (const auto layout :
         {defocus::YuvImage::Layout::I420, defocus::YuvImage::Layout::Nv12, defocus::YuvImage::Layout::Yuyv}) {
        const defocus::YuvImage yuv = opencvYuv(bgr, layout);
        // OpenCV's own way back, from its packed layout.
        cv::Mat reference;
        cv::cvtColor(packedPlanes(yuv), reference, opencvToBgr(layout));
        const cv::Mat ours = defocus::yuvToBgr(yuv);
        ASSERT_EQ(ours.type(), CV_8UC3);
        EXPECT_LE(cv::norm(ours, reference, cv::NORM_INF), 1.0) << layoutName(layout);
        EXPECT_TRUE(identical(defocus::yuvToBgr(padded(yuv)), ours)) << "planes with padded rows";
    }
    // Full range (JPEG): OpenCV's YCrCb on 4:4:4 planes, each block's chroma repeated.
    defocus::YuvImage full = opencvYuv(bgr, defocus::YuvImage::Layout::I420);
    full.range = defocus::YuvImage::Range::Full;
    cv::Mat cb, cr, ycrcb, reference;
    cv::resize(full.u, cb, full.y.size(), 0, 0, cv::INTER_NEAREST);
    cv::resize(full.v, cr, full.y.size(), 0, 0, cv::INTER_NEAREST);
    cv::merge(std::vector<cv::Mat>{full.y, cr, cb}, ycrcb);
    cv::cvtColor(ycrcb, reference, cv::COLOR_YCrCb2BGR);
    EXPECT_LE(cv::norm(defocus::yuvToBgr(full), reference, cv::NORM_INF), 1.0) << "BT.601 full range";
    // BT.709: black, white and the primaries, limited and full, from their Y'CbCr by the standard.
    const double kr = 0.2126, kb = 0.0722, kg = 1.0 - kr - kb;
    for (const auto range : {defocus::YuvImage::Range::Limited, defocus::YuvImage::Range::Full}) {
        const bool limited = range == defocus::YuvImage::Range::Limited;
        for (const cv::Vec3d& rgb : {cv::Vec3d(0, 0, 0), cv::Vec3d(1, 1, 1), cv::Vec3d(1, 0, 0), cv::Vec3d(0, 1, 0),
                                    cv::Vec3d(0, 0, 1)}) {
            const double luma = kr * rgb[0] + kg * rgb[1] + kb * rgb[2];
            const double pb = (rgb[2] - luma) / (2 * (1 - kb)), pr = (rgb[0] - luma) / (2 * (1 - kr));
            const auto code = [](double v) { return cv::saturate_cast<uchar>(std::lround(v)); };
            defocus::YuvImage one;
            one.matrix = defocus::YuvImage::Matrix::Bt709;
            one.range = range;
            one.y = cv::Mat(2, 2, CV_8UC1, cv::Scalar(code(limited ? 16 + 219 * luma : 255 * luma)));
            one.u = cv::Mat(1, 1, CV_8UC1, cv::Scalar(code(limited ? 128 + 224 * pb : 128 + 255 * pb)));
            one.v = cv::Mat(1, 1, CV_8UC1, cv::Scalar(code(limited ? 128 + 224 * pr : 128 + 255 * pr)));
            const cv::Vec3b out = defocus::yuvToBgr(one).at<cv::Vec3b>(1, 1);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(out[2 - c], 255 * rgb[c], 2.0)
                    << (limited ? "limited" : "full") << " R'G'B' " << rgb << " channel " << c;
        }
    }
}

// Defects caught: planes of the wrong type or size taken (read past a plane's end), an NV12
// image's stray Cr plane or an I420's missing one passing, a YUYV image of an odd width (its last
// pixel's Cr beyond the row) or of single-channel bytes; each refused in one line naming it.
TEST(LibraryYuv, PlanesOfTheWrongShapeAreInputErrorsNamingThem)
{
    const cv::Mat bgr(48, 64, CV_8UC3, cv::Scalar(40, 80, 120));
    const defocus::YuvImage good = opencvYuv(bgr, defocus::YuvImage::Layout::I420);
    const auto message = [](const defocus::YuvImage& yuv) {
        try {
            defocus::yuvToBgr(yuv);
        } catch (const defocus::InputError& error) {
            return std::string(error.what());
        }
        return std::string("accepted");
    };
    defocus::YuvImage wrong = good;
    wrong.y = cv::Mat(48, 64, CV_16UC1);
    EXPECT_NE(message(wrong).find("luma plane (y)"), std::string::npos) << message(wrong);
    wrong = good;
    wrong.u = good.u.rowRange(0, 20);
    EXPECT_NE(message(wrong).find("Cb plane (u) is CV_8UC1 32x20; expected CV_8UC1 32x24"), std::string::npos)
        << message(wrong);
    wrong = good;
    wrong.v = cv::Mat();
    EXPECT_NE(message(wrong).find("Cr plane (v) is empty"), std::string::npos) << message(wrong);
    wrong = opencvYuv(bgr, defocus::YuvImage::Layout::Nv12);
    wrong.v = good.v;
    EXPECT_NE(message(wrong).find("an NV12 image has Cb and Cr in u"), std::string::npos) << message(wrong);
    wrong.v = cv::Mat();
    wrong.layout = defocus::YuvImage::Layout::I420;
    EXPECT_NE(message(wrong).find("Cb plane (u) is CV_8UC2"), std::string::npos) << message(wrong);
    const defocus::YuvImage pairs = opencvYuv(bgr, defocus::YuvImage::Layout::Yuyv);
    wrong = pairs;
    wrong.y = pairs.y.colRange(0, 63);
    EXPECT_NE(message(wrong).find("a YUYV image is 63 pixels wide"), std::string::npos) << message(wrong);
    wrong = pairs;
    wrong.y = good.y;
    EXPECT_NE(message(wrong).find("a YUYV image's y is CV_8UC1"), std::string::npos) << message(wrong);
    wrong = pairs;
    wrong.u = good.u;
    EXPECT_NE(message(wrong).find("a YUYV image has Cb and Cr in y"), std::string::npos) << message(wrong);
    EXPECT_EQ(message(pairs), "accepted");
}

// Defects caught: Y'CbCr in that is not its BGR's result, on either path (the GPU's planes and
// conversion pass under DEFOCUS_DEPTH_PREP=gpu, library_gpu_defaults; the CPU's conversion here):
// a conversion that differs from yuvToBgr() by a level, planes with padded rows read as packed, a
// frame all in focus that passes another colour through or, for BGRA or linear output, the planes'
// conversion unchanged; frames in flight or the contact sheet losing the planes. Every preset,
// both kernels, the plan on and off.
TEST(LibraryYuv, YuvInIsTheResultOfItsBgrOnEveryPreset)
{
    const Pair pair = bundled(9);
    cv::Mat bgr = cv::imread(pair.color.string(), cv::IMREAD_COLOR), depth;
    cv::resize(bgr, bgr, {320, 240}, 0, 0, cv::INTER_AREA);
    cv::resize(cv::imread(pair.depth.string(), cv::IMREAD_UNCHANGED), depth, {320, 240}, 0, 0, cv::INTER_NEAREST);
    const cv::Mat flat(depth.size(), CV_16UC1, cv::Scalar(5000)); // all at the focus, 1 m
    for (const auto layout :
         {defocus::YuvImage::Layout::I420, defocus::YuvImage::Layout::Nv12, defocus::YuvImage::Layout::Yuyv}) {
        defocus::YuvImage yuv = padded(opencvYuv(bgr, layout));
        yuv.matrix = defocus::YuvImage::Matrix::Bt709; // any: the same conversion either way
        const cv::Mat converted = defocus::yuvToBgr(yuv);
        for (const auto preset : {defocus::Quality::Preset::Fast, defocus::Quality::Preset::Balanced,
                                  defocus::Quality::Preset::High})
            for (const auto kernel : {defocus::Quality::Hexagon::Rhombi, defocus::Quality::Hexagon::McIntosh})
                for (const bool alwaysOn : {false, true}) {
                    defocus::Settings settings = presetSettings(preset, kernel);
                    settings.quality.alwaysOn = alwaysOn;
                    const std::string what = fmt::format(
                        "{}, {}, {}, plan {}", layoutName(layout),
                        defocus::qualityName(preset), kernel == defocus::Quality::Hexagon::Rhombi ? "rhombi" : "mcintosh",
                        alwaysOn ? "off" : "on");
                    std::optional<defocus::Filter> filter;
                    try {
                        filter.emplace(settings);
                    } catch (const defocus::GlError& error) {
                        GTEST_SKIP() << "no OpenGL 4.5: " << error.what();
                    }
                    for (const cv::Mat& d : {depth, flat}) {
                        const cv::Mat expected = filter->process(converted, d);
                        EXPECT_TRUE(identical(filter->process(yuv, d), expected))
                            << what << (d.data == flat.data ? ", all in focus" : "");
                    }
                    if (preset != defocus::Quality::Preset::Balanced || kernel != defocus::Quality::Hexagon::Rhombi)
                        continue;
                    // In flight, and the contact sheet's frame processed again from the planes.
                    const cv::Mat expected = filter->process(converted, depth);
                    filter->submit(yuv, depth);
                    filter->submit(yuv, flat);
                    EXPECT_TRUE(identical(filter->receive().value(), expected)) << what << ", in flight";
                    filter->receive();
                    const cv::Mat out = filter->process(yuv, depth);
                    filter->contactSheet();
                    EXPECT_TRUE(identical(filter->process(yuv, depth), out)) << what << ", after a contact sheet";
                    // The other outputs, blurred and all in focus (where the planes' conversion is
                    // the output's source, made BGRA or linear as the BGR frame is).
                    for (const auto output : {defocus::Settings::Output::Srgb8Bgra, defocus::Settings::Output::Linear32F}) {
                        defocus::Settings other = settings;
                        other.output = output;
                        filter->setSettings(other);
                        for (const cv::Mat& d : {depth, flat})
                            EXPECT_TRUE(identical(filter->process(yuv, d), filter->process(converted, d)))
                                << what << (output == defocus::Settings::Output::Linear32F ? ", linear" : ", BGRA")
                                << (d.data == flat.data ? ", all in focus" : "");
                    }
                }
    }
}

// Defects caught: process(Frame) or submit(Frame) taking the wrong colour (BGR where the frame
// holds Y'CbCr planes, or the reverse), 16-bit depth read in the settings' units when the frame
// states others (the clip's 5000 a metre read as 1000: every depth five times farther), or
// converted to metres when the units agree, or the frame's timestamp left out (the follow
// autofocus then steps by 1/30 s instead of the frames' 0.5 s apart).
TEST_F(Library, AFrameAsASourceGivesItIsItsImagesResult)
{
    defocus::Frame frame;
    frame.color = color_;
    frame.depth = depth_; // 16-bit, 5000 a metre, as the settings say
    frame.depthScale = 5000.0;
    const cv::Mat direct = filter_->process(color_, depth_);
    EXPECT_TRUE(identical(filter_->process(frame), direct)) << "BGR, the settings' units";

    defocus::Settings millimetres = settings_;
    millimetres.depthScale = 1000.0;
    filter_->setSettings(millimetres);
    EXPECT_TRUE(identical(filter_->process(frame), filter_->process(color_, defocus::depthMetres(frame))))
        << "BGR, other units than the settings'";
    EXPECT_FALSE(identical(filter_->process(frame), filter_->process(color_, depth_)))
        << "the clip read in millimetres must differ, or the case above shows nothing";
    filter_->setSettings(settings_);

    defocus::Frame planes = frame;
    planes.color = cv::Mat();
    planes.yuv = opencvYuv(color_, defocus::YuvImage::Layout::Nv12);
    planes.yuv.matrix = defocus::YuvImage::Matrix::Bt601;
    const cv::Mat fromPlanes = filter_->process(planes.yuv, depth_);
    EXPECT_TRUE(identical(filter_->process(planes), fromPlanes)) << "Y'CbCr planes";
    EXPECT_TRUE(identical(defocus::colorBgr(planes), defocus::yuvToBgr(planes.yuv)));
    EXPECT_EQ(defocus::colorSize(planes), color_.size());

    filter_->submit(planes);
    filter_->submit(frame);
    EXPECT_TRUE(identical(filter_->receive().value(), fromPlanes)) << "Y'CbCr planes, in flight";
    EXPECT_TRUE(identical(filter_->receive().value(), direct)) << "BGR, in flight";

    // The timestamp: follow autofocus moves by the time between frames.
    defocus::Settings follow = settings_;
    follow.autofocus.mode = defocus::AutofocusOptions::Mode::Follow;
    const cv::Mat near(depth_.size(), CV_16UC1, cv::Scalar(2500)); // 0.5 m: the focus glides there
    filter_->setSettings(follow);
    const auto focusAfterTwo = [&](bool asFrames, double firstS, double secondS) {
        filter_->reset();
        for (int i = 0; i < 2; ++i) {
            frame.depth = i == 0 ? depth_ : near;
            frame.timestampS = i == 0 ? firstS : secondS;
            if (asFrames)
                filter_->process(frame);
            else
                filter_->process(color_, frame.depth, frame.timestampS);
        }
        return filter_->lastFrame().focusM;
    };
    const double followed = focusAfterTwo(false, 1.0, 1.5); // 0 would be "unknown"
    EXPECT_EQ(focusAfterTwo(true, 1.0, 1.5), followed);
    EXPECT_NE(focusAfterTwo(true, 0.0, 0.0), followed) << "the frames' 0.5 s must show, or the case above shows nothing";
}

// Defects caught: SourceSettings::readThreads not reaching the reading (no frame is read before
// next() asks: the reads of frames 1 and 2 are watched for with inotify, right after the Source is
// made), and frames decoded ahead given in another order, paired with another depth or changed.
TEST(LibrarySource, ReadThreadsDecodeAheadAndGiveTheClipsFramesAsTheyAre)
{
    const fs::path dir = defocus::test::scratchDir("LibrarySource_read_threads");
    fs::create_directories(dir / "colour");
    fs::create_directories(dir / "depth");
    for (int k = 0; k < 3; ++k) {
        const Pair pair = bundled(4 + k);
        fs::copy_file(pair.color, dir / "colour" / fmt::format("{:04}.png", k));
        fs::copy_file(pair.depth, dir / "depth" / fmt::format("{:04}.png", k));
    }
    defocus::SourceSettings settings;
    settings.input = (dir / "colour").string();
    settings.depth = (dir / "depth").string();
    settings.depthScale = 5000;
    const int watch = inotify_init1(IN_NONBLOCK);
    ASSERT_GE(watch, 0);
    ASSERT_GE(inotify_add_watch(watch, (dir / "colour").c_str(), IN_CLOSE_NOWRITE), 0);
    settings.readThreads = 2;
    defocus::Source ahead(settings);
    std::set<std::string> read;
    for (int i = 0; i < 1000 && !(read.count("0001.png") && read.count("0002.png")); ++i) {
        alignas(inotify_event) char buffer[4096];
        for (ssize_t n; (n = ::read(watch, buffer, sizeof buffer)) > 0;)
            for (char* at = buffer; at < buffer + n;) {
                const auto* event = reinterpret_cast<const inotify_event*>(at);
                if (event->len > 0)
                    read.insert(event->name);
                at += sizeof(inotify_event) + event->len;
            }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ::close(watch);
    EXPECT_TRUE(read.count("0001.png") && read.count("0002.png")) << "frames 1 and 2 not read ahead of next()";
    settings.readThreads = 0;
    defocus::Source inTurn(settings);
    for (int k = 0; k < 3; ++k) {
        const auto a = ahead.next(), b = inTurn.next();
        ASSERT_TRUE(a && b) << k;
        EXPECT_TRUE(identical(a->color, b->color)) << k;
        EXPECT_TRUE(identical(a->depth, b->depth)) << k;
        EXPECT_EQ(a->name, b->name);
        EXPECT_EQ(a->index, b->index);
    }
    EXPECT_FALSE(ahead.next());
    EXPECT_FALSE(inTurn.next());
}
