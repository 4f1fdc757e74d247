// SPDX-License-Identifier: LGPL-2.1-or-later
// Autofocus without GL: the weighted window measurement, the spring's step response on noisy
// synthetic depth, tap to focus, invalid windows, and convergence on the bundled TUM clip.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "filter/Autofocus.hpp"
#include "filter/DepthPrep.hpp"
#include "sources/FrameSource.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::unique_ptr<FrameSource> openTum()
{
    SourceOptions options;
    options.input = test::dataDir() / "tum_fr1_rpy";
    return openSource(options);
}

cv::Mat flat(cv::Size size, float metres)
{
    return cv::Mat(size, CV_32F, cv::Scalar(metres));
}

TEST(Autofocus, UniformDepthIsMeasuredExactly)
{
    const auto measured = measureFocus(flat({320, 240}, 1.7f), {});
    ASSERT_TRUE(measured);
    EXPECT_NEAR(*measured, static_cast<double>(1.7f), 1e-9);
}

TEST(Autofocus, WindowAveragesInDioptresWithSymmetricWeights)
{
    // Left half of the window at 1 m, right half at 2 m: the weights are symmetric, so the mean
    // of 1/z is (1 + 0.5) / 2 = 0.75 D, i.e. 1.333 m (not the 1.5 m of a mean in metres).
    cv::Mat depth = flat({400, 400}, 1.0f);
    depth(cv::Rect(200, 0, 200, 400)).setTo(2.0f);
    const auto measured = measureFocus(depth, {});
    ASSERT_TRUE(measured);
    EXPECT_NEAR(*measured, 1.0 / 0.75, 1e-6);
}

TEST(Autofocus, WeightsFallParabolicallyTowardTheEdges)
{
    // A 2 m column at the window's centre pulls the focus further than the same column near its
    // edge, where the weight 1 - u^2 is small; outside the window it does nothing at all.
    const cv::Size size(400, 400); // window: 40 x 40 px centred at (200, 200)
    const auto withColumn = [&](int x) {
        cv::Mat depth = flat(size, 1.0f);
        depth.col(x).setTo(2.0f);
        return *measureFocus(depth, {});
    };
    const double centre = withColumn(200), edge = withColumn(181), outside = withColumn(150);
    EXPECT_GT(centre, edge);
    EXPECT_GT(edge, 1.0);
    EXPECT_DOUBLE_EQ(outside, 1.0);
    // Column 200's centre sits at u = 0.5 / 20, column 181's at u = -18.5 / 20; each column's share
    // of the weight is w / sum(w) with sum over 40 columns of 1 - u^2 = 40 * (2/3) (+ a little).
    const auto share = [](double u) {
        double sum = 0.0;
        for (int i = 180; i < 220; ++i) {
            const double v = (i + 0.5 - 200.0) / 20.0;
            sum += 1.0 - v * v;
        }
        return (1.0 - u * u) / sum;
    };
    EXPECT_NEAR(1.0 / centre, 1.0 - 0.5 * share(0.5 / 20.0), 1e-9);
    EXPECT_NEAR(1.0 / edge, 1.0 - 0.5 * share(-18.5 / 20.0), 1e-9);
}

TEST(Autofocus, InvalidPixelsAreIgnoredAndTheWeightsRenormalised)
{
    cv::Mat depth = flat({320, 240}, 1.5f);
    cv::RNG rng(7);
    for (int i = 0; i < 20000; ++i) {
        const float bad[] = {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()};
        depth.at<float>(rng.uniform(0, 240), rng.uniform(0, 320)) = bad[rng.uniform(0, 4)];
    }
    const auto measured = measureFocus(depth, {});
    ASSERT_TRUE(measured);
    EXPECT_NEAR(*measured, 1.5, 1e-6);

    depth(cv::Rect(100, 80, 120, 80)).setTo(0.0f); // the whole window
    EXPECT_FALSE(measureFocus(depth, {}));
    EXPECT_FALSE(measureFocus(cv::Mat(), {}));
}

TEST(Autofocus, FrameIntervalUsesTimestampsOrTheFallback)
{
    EXPECT_DOUBLE_EQ(frameInterval(10.0, 10.04, 0.5), 10.04 - 10.0);
    EXPECT_DOUBLE_EQ(frameInterval(0.0, 0.0, 0.5), 0.5);     // no timestamps
    EXPECT_DOUBLE_EQ(frameInterval(10.0, 9.0, 0.5), 0.5);    // backwards (a clip looped)
    EXPECT_DOUBLE_EQ(frameInterval(10.0, 12.0, 0.5), 0.5);   // a gap longer than 1 s
    EXPECT_DOUBLE_EQ(frameInterval(0.0, 1e9, 0.5), 0.5);     // the first frame
}

TEST(Autofocus, SpringStepIsExactWhateverTheFrameRate)
{
    // The step is solved in closed form, so 1 s in one step or in 240 steps lands on the same
    // focus, and (1 + t/tau) exp(-t/tau) of the way is left, in dioptres.
    AutofocusSettings settings;
    settings.timeConstantS = 0.25;
    settings.deadBandDioptres = 0.0;
    Autofocus once(settings), many(settings);
    for (Autofocus* af : {&once, &many}) {
        af->update(flat({64, 48}, 1.0f), 1.0 / 30);  // first measurement: taken at once
        ASSERT_DOUBLE_EQ(af->focusM(), 1.0);
        af->retarget(flat({64, 48}, 4.0f));           // target 0.25 D, no time passed
    }
    once.advance(1.0);
    for (int i = 0; i < 240; ++i)
        many.advance(1.0 / 240);
    const double left = (1.0 + 4.0) * std::exp(-4.0); // t / tau = 4
    EXPECT_NEAR(1.0 / once.focusM(), 0.25 + 0.75 * left, 1e-12);
    EXPECT_NEAR(1.0 / many.focusM(), 1.0 / once.focusM(), 1e-12);
}

/// A 30 Hz stream of noisy Kinect-like depth: per-pixel noise sigma = 0.0045 z^2 m (three times
/// the ~1.4 mm * z^2 random error reported for the Kinect v1), 10 % dropouts, and the whole
/// frame jittering by 0.5 % (a subject swaying). Returns the focus, metres, per frame.
struct StepRun {
    std::vector<double> focusM;
    std::vector<double> targetM;
    std::size_t stepFrame = 0;
};

StepRun runStep(double fromM, double toM, double tau, double seconds = 4.0, double stepAtS = 1.0)
{
    std::mt19937 rng(1234);
    std::normal_distribution<float> unit(0.0f, 1.0f);
    std::uniform_real_distribution<float> chance(0.0f, 1.0f);
    AutofocusSettings settings;
    settings.timeConstantS = tau;
    Autofocus af(settings);
    StepRun run;
    const double dt = 1.0 / 30.0;
    run.stepFrame = static_cast<std::size_t>(std::lround(stepAtS / dt));
    const auto frames = static_cast<std::size_t>(std::lround(seconds / dt));
    cv::Mat depth(120, 160, CV_32F);
    for (std::size_t i = 0; i < frames; ++i) {
        const float z = static_cast<float>(i < run.stepFrame ? fromM : toM) * (1.0f + 0.005f * unit(rng));
        for (int y = 0; y < depth.rows; ++y)
            for (int x = 0; x < depth.cols; ++x)
                depth.at<float>(y, x) = chance(rng) < 0.1f ? 0.0f : z + 0.0045f * z * z * unit(rng);
        run.focusM.push_back(af.update(depth, dt));
        run.targetM.push_back(af.targetM());
    }
    return run;
}

void expectCleanStep(const StepRun& run, double fromM, double toM, double tau)
{
    const double step = 1.0 / toM - 1.0 / fromM; // dioptres, signed
    const double dt = 1.0 / 30.0;
    double extreme = run.focusM[run.stepFrame]; // the farthest past the target, in metres
    int reversals = 0;
    double previousMove = 0.0;
    for (std::size_t i = run.stepFrame; i < run.focusM.size(); ++i) {
        const double d = 1.0 / run.focusM[i];
        const double t = static_cast<double>(i - run.stepFrame + 1) * dt; // time since the step began
        extreme = toM > fromM ? std::max(extreme, run.focusM[i]) : std::min(extreme, run.focusM[i]);
        // Settled within 5 % of the step (in dioptres, the space blur is linear in) after 5 tau.
        if (t >= 5.0 * tau) {
            EXPECT_LT(std::abs(d - 1.0 / toM), 0.05 * std::abs(step)) << "frame " << i << ", t = " << t << " s";
        }
        if (i > run.stepFrame) {
            const double move = d - 1.0 / run.focusM[i - 1];
            if (std::abs(move) > 1e-9) {
                if (previousMove != 0.0 && (move > 0) != (previousMove > 0))
                    ++reversals;
                previousMove = move;
            }
        }
    }
    // Overshoot under 5 % of the step, in metres.
    const double overshoot = std::max(0.0, toM > fromM ? extreme - toM : toM - extreme);
    EXPECT_LT(overshoot, 0.05 * std::abs(toM - fromM));
    EXPECT_EQ(reversals, 0) << "the focus oscillated";
    // Before the step, and once settled, the dead band holds the target: no hunting.
    for (std::size_t i = 1; i < run.stepFrame; ++i)
        EXPECT_DOUBLE_EQ(run.targetM[i], run.targetM[0]) << "hunting at frame " << i;
    const auto settledFrom = run.stepFrame + static_cast<std::size_t>(std::ceil(0.1 / dt));
    for (std::size_t i = settledFrom; i < run.targetM.size(); ++i)
        EXPECT_DOUBLE_EQ(run.targetM[i], run.targetM[settledFrom]) << "hunting at frame " << i;
    EXPECT_NEAR(run.focusM.back(), toM, 0.01 * toM);
    EXPECT_NEAR(run.focusM[run.stepFrame - 1], fromM, 0.01 * fromM);
}

TEST(Autofocus, StepFromOneToThreeMetresIsCriticallyDampedOnNoisyDepth)
{
    const double tau = 0.25;
    const StepRun run = runStep(1.0, 3.0, tau);
    expectCleanStep(run, 1.0, 3.0, tau);
}

TEST(Autofocus, StepFromThreeToOneMetreIsCriticallyDampedOnNoisyDepth)
{
    const double tau = 0.25;
    const StepRun run = runStep(3.0, 1.0, tau);
    expectCleanStep(run, 3.0, 1.0, tau);
}

TEST(Autofocus, ShortTimeConstantStillSettlesCleanly)
{
    const double tau = 0.1;
    const StepRun run = runStep(1.0, 3.0, tau, 2.0);
    expectCleanStep(run, 1.0, 3.0, tau);
}

TEST(Autofocus, TapFocusesOnTheClickedObject)
{
    // Background at 3 m; a 60 x 60 px box at 1.2 m off-centre; the centre sees the background.
    cv::Mat depth = flat({640, 480}, 3.0f);
    depth(cv::Rect(80, 60, 60, 60)).setTo(1.2f);
    AutofocusSettings settings;
    settings.timeConstantS = 0.0;
    Autofocus af(settings);
    EXPECT_NEAR(af.update(depth, 1.0 / 30), 3.0, 1e-6);
    af.tap({110.5 / 640, 90.5 / 480}, 640.0 / 480);
    EXPECT_TRUE(af.tapped());
    EXPECT_NEAR(af.update(depth, 1.0 / 30), 1.2, 1e-6);
    // The tap region is 2 % of the width (12.8 px) square: a click 8 px inside the box's edge
    // still sees only the box.
    af.tap({88.5 / 640, 68.5 / 480}, 640.0 / 480);
    EXPECT_NEAR(af.update(depth, 1.0 / 30), 1.2, 1e-6);
    af.recentre();
    EXPECT_FALSE(af.tapped());
    EXPECT_NEAR(af.update(depth, 1.0 / 30), 3.0, 1e-6);
}

TEST(Autofocus, TapOnTheTumClipMatchesTheDepthThere)
{
    auto source = openTum();
    const auto frame = source->next();
    ASSERT_TRUE(frame && !frame->depth.empty());
    AutofocusSettings settings;
    settings.timeConstantS = 0.0;
    Autofocus af(settings);
    af.update(frame->depth, 1.0 / 30);
    // Tap where the median of a 13 px square differs most from the centre's.
    const double centre = af.focusM();
    cv::Point best;
    double bestDepth = centre;
    for (int y = 40; y < 440; y += 40)
        for (int x = 40; x < 600; x += 40) {
            const cv::Mat patch = frame->depth(cv::Rect(x - 6, y - 6, 13, 13));
            std::vector<float> valid;
            for (const float z : cv::Mat_<float>(patch.clone()))
                if (isValidDepth(z))
                    valid.push_back(z);
            if (valid.size() < 150)
                continue;
            std::nth_element(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2), valid.end());
            const double median = valid[valid.size() / 2];
            if (std::abs(1.0 / median - 1.0 / centre) > std::abs(1.0 / bestDepth - 1.0 / centre)) {
                best = {x, y};
                bestDepth = median;
            }
        }
    ASSERT_GT(std::abs(bestDepth - centre), 0.2 * centre) << "the clip should have depth away from the centre";
    af.tap({(best.x + 0.5) / 640, (best.y + 0.5) / 480}, 640.0 / 480);
    EXPECT_NEAR(af.update(frame->depth, 1.0 / 30), bestDepth, 0.03 * bestDepth) << "tapped at " << best;
}

TEST(Autofocus, WindowWithNoValidDepthKeepsThePreviousFocus)
{
    AutofocusSettings settings;
    settings.timeConstantS = 0.1;
    Autofocus af(settings, 5.0);
    // No valid depth anywhere yet: the initial focus stays.
    EXPECT_DOUBLE_EQ(af.update(flat({160, 120}, 0.0f), 1.0 / 30), 5.0);
    EXPECT_DOUBLE_EQ(af.update(cv::Mat(), 1.0 / 30), 5.0);
    for (int i = 0; i < 30; ++i)
        af.update(flat({160, 120}, 2.0f), 1.0 / 30);
    EXPECT_NEAR(af.focusM(), 2.0, 1e-6);
    cv::Mat holes = flat({160, 120}, 7.0f);
    holes(cv::Rect(60, 40, 40, 40)).setTo(static_cast<float>(kNaN)); // covers the centre window
    for (int i = 0; i < 30; ++i)
        EXPECT_NEAR(af.update(holes, 1.0 / 30), 2.0, 1e-6);
    EXPECT_NEAR(af.targetM(), 2.0, 1e-6);
}

TEST(Autofocus, ConvergesToTheSubjectOfTheTumClip)
{
    // A short time constant so that the ten frames (0.3 s) are enough; the reference is the
    // median depth of the central 10 % window of the last frame (centreDepth()). The two differ
    // by the weighting (parabolic mean of 1/z vs. median) and the dead band, 0.02 D.
    auto source = openTum();
    AutofocusSettings settings;
    settings.timeConstantS = 0.03;
    Autofocus af(settings, 10.0);
    double previous = 0.0;
    cv::Mat lastDepth;
    std::size_t frames = 0;
    while (auto frame = source->next()) {
        af.update(frame->depth, frameInterval(previous, frame->timestampS, 1.0 / 30));
        previous = frame->timestampS;
        lastDepth = frame->depth;
        ++frames;
    }
    ASSERT_EQ(frames, 10u);
    const double reference = centreDepth(lastDepth, 0.1, 0.0f);
    ASSERT_GT(reference, 0.3);
    std::printf("autofocus %.3f m, median of the centre window %.3f m\n", af.focusM(), reference);
    EXPECT_NEAR(af.focusM(), reference, 0.05 * reference);
    EXPECT_NEAR(1.0 / af.focusM(), 1.0 / reference, 0.03);
}

} // namespace
} // namespace defocus
