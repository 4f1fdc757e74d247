// SPDX-License-Identifier: LGPL-2.1-or-later
// Depth prep and the scene measurement on the GPU against the same steps on the CPU: one filled
// depth, one measurement, one plan, one frame out, on every preset and both kernels.
#include <cmath>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "filter/DepthPrep.hpp"
#include "filter/Lens.hpp"
#include "filter/Pipeline.hpp"
#include "filter/Presets.hpp"
#include "sources/FrameSource.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

/// The first `count` frames of the bundled TUM clip.
std::vector<Frame> tumFrames(std::size_t count)
{
    auto source = openSource({test::dataDir() / "tum_fr1_rpy", std::nullopt, std::nullopt});
    std::vector<Frame> frames;
    while (frames.size() < count)
        if (auto frame = source->next())
            frames.push_back(*frame);
        else
            break;
    EXPECT_EQ(frames.size(), count);
    for (const Frame& frame : frames)
        EXPECT_FALSE(frame.depth.empty()) << frame.name;
    return frames;
}

Frame tumFrame()
{
    const std::vector<Frame> frames = tumFrames(1);
    return frames.empty() ? Frame{} : frames.front();
}

LensSettings tumLens()
{
    LensSettings lens;
    lens.focusM = 1.0;
    lens.fNumber = 1.4;
    lens.maxCocPx = 32.0;
    return lens;
}

/// The largest difference of two filled depths relative to the CPU's, over every pixel.
double largestRelativeDifference(const cv::Mat& gpu, const cv::Mat& cpu)
{
    cv::Mat difference;
    cv::absdiff(gpu, cpu, difference);
    cv::divide(difference, cpu, difference);
    double largest = 0.0;
    cv::minMaxLoc(difference, nullptr, &largest);
    return largest;
}

using DepthPrepGpu = test::GLTest;

/// Pipelines with depth prep on the GPU and on the CPU, run on one frame.
struct SideBySide {
    Pipeline gpu, cpu;
    SideBySide()
    {
        gpu.prepareOnGpu(true); // not the default on llvmpipe
        cpu.prepareOnGpu(false);
    }
    void run(const Frame& frame, const LensSettings& lens, const QualitySettings& quality, cv::Mat* gpuOut = nullptr,
             cv::Mat* cpuOut = nullptr)
    {
        const cv::Mat a = gpu.run(frame, lens, quality), b = cpu.run(frame, lens, quality);
        if (gpuOut)
            *gpuOut = a;
        if (cpuOut)
            *cpuOut = b;
    }
};

// Defects caught: the GPU's nearest resize taking other source pixels than cv::resize's; a push
// level averaging the wrong block (2x2 where a size is odd) or skipping the weights; the pull
// missing a level or blending the wrong way; the holes' count off. A filled depth is the same
// measured depths and interpolations of them, so the two agree to float rounding: sums, products
// and interpolations over 10 levels, each a few float ulps (1.2e-7), under 1e-4 of the depth (the
// odd frame's area weights: 1.2e-5; the others 1e-5 or less). The planted 2x2 block: 0.2 to 0.5.
TEST_F(DepthPrepGpu, GpuFillsHolesAsTheCpuDoesAtEverySize)
{
    const Frame frame = tumFrame();
    ASSERT_FALSE(frame.depth.empty());
    SideBySide pipelines;
    // The depth as it came, half of it, and an odd size (213x160); then an odd frame (637x477:
    // odd pyramid levels from the first) with a hole so large that the coarsest levels fill it.
    for (const cv::Size size : {frame.depth.size(), cv::Size(320, 240), cv::Size(213, 160), cv::Size()}) {
        Frame resized = frame;
        if (size.empty()) {
            const cv::Rect odd(0, 0, 637, 477);
            resized.color = frame.color(odd).clone();
            resized.depth = frame.depth(odd).clone();
            resized.depth(cv::Rect(100, 100, 400, 300)).setTo(0.0f);
        } else {
            cv::resize(frame.depth, resized.depth, size, 0, 0, cv::INTER_NEAREST);
        }
        pipelines.run(resized, tumLens(), QualitySettings{});
        const std::string where = size.empty() ? "637x477 with a large hole"
                                               : std::to_string(size.width) + "x" + std::to_string(size.height);
        EXPECT_GT(pipelines.cpu.invalidDepthFraction(), 0.05) << where << ": the Kinect frame has holes";
        EXPECT_DOUBLE_EQ(pipelines.gpu.invalidDepthFraction(), pipelines.cpu.invalidDepthFraction()) << where;
        const cv::Mat& gpu = pipelines.gpu.filledDepth();
        const cv::Mat& cpu = pipelines.cpu.filledDepth();
        ASSERT_EQ(gpu.size(), resized.color.size());
        EXPECT_LE(largestRelativeDifference(gpu, cpu), 1e-4) << where;
    }
}

// Defects caught: a frame with no depth, or none of it valid, left unfilled (0 m, a CoC at the
// clamp everywhere) or filled with something other than the focus distance.
TEST_F(DepthPrepGpu, GpuPutsAFrameWithoutMeasurementsAtTheFocusDistance)
{
    const Frame tum = tumFrame();
    SideBySide pipelines;
    const LensSettings lens = tumLens();
    for (const bool noDepth : {true, false}) {
        Frame frame = tum;
        frame.depth = noDepth ? cv::Mat() : cv::Mat(60, 80, CV_32F, cv::Scalar(0.0f));
        // The all-in-focus exit would skip depth prep: the views run it.
        QualitySettings quality;
        quality.adaptive = false;
        pipelines.run(frame, lens, quality);
        const cv::Mat& gpu = pipelines.gpu.filledDepth();
        double lo = 0.0, hi = 0.0;
        cv::minMaxLoc(gpu, &lo, &hi);
        EXPECT_EQ(lo, lens.focusM) << (noDepth ? "no depth" : "no valid depth");
        EXPECT_EQ(hi, lens.focusM) << (noDepth ? "no depth" : "no valid depth");
        EXPECT_EQ(pipelines.gpu.invalidDepthFraction(), 1.0);
        EXPECT_EQ(pipelines.cpu.invalidDepthFraction(), 1.0);
    }
}

// Defects caught: the lights' edges not moved to their lights' depth on the GPU (or moved
// further: a pixel to a farther light, a light's neighbour that is not above white; a light's
// sliver beside a bar left at the bar's depth: this frame has such slivers), so that
// the sprites' light and the gather's disagree with the CPU's.
TEST_F(DepthPrepGpu, GpuPutsLightEdgesAtTheirLightsDepthAsTheCpuDoes)
{
    const Frame frame = test::railingLights();
    // The CPU's own step, to know that this frame has edges to move.
    PreparedDepth filled = prepareDepth(frame.depth, frame.color.size(), 1.0f);
    ASSERT_GT(putLightEdgesAtTheirLightsDepth(frame.color, filled.metres), 50u);
    LensSettings lens;
    lens.focusM = 2.0;
    lens.fNumber = 2.0;
    SideBySide pipelines;
    pipelines.run(frame, lens, presetSettings("balanced"));
    ASSERT_TRUE(pipelines.gpu.plan().highlightSprites) << "the step runs only for frames with sprites";
    EXPECT_LE(largestRelativeDifference(pipelines.gpu.filledDepth(), pipelines.cpu.filledDepth()), 1e-4);
}

// Defects caught: the GPU measurement's tiles transposed or offset, a tile's range missing its
// edge pixels, the histogram counting a bin twice, 8-bit highlights judged on other than the
// camera's clipped channels; any of which changes the plan: its tiles, its sizes, its sprites.
// Tile ranges are the CoC of min and max of depths that agree to 1e-5 on these even-sized frames
// (above), at most ~96 px/m of CoC a metre at this lens near 1 m: within 1e-3 px.
// Luminance sums are of the same values in another order: within 1e-5.
TEST_F(DepthPrepGpu, GpuMeasuresTheSceneAsTheCpuDoes)
{
    const Frame tum = tumFrame();
    const Frame lights = test::railingLights();
    SideBySide pipelines;
    for (const Frame* frame : std::initializer_list<const Frame*>{&tum, &lights}) {
        pipelines.run(*frame, tumLens(), presetSettings("balanced"));
        const SceneAnalysis& a = pipelines.gpu.analysis();
        const SceneAnalysis& b = pipelines.cpu.analysis();
        const std::string which = frame == &tum ? "tum (8-bit)" : "railing-lights (float)";
        ASSERT_EQ(a.tiles, b.tiles) << which;
        EXPECT_LE(cv::norm(a.tileMinCoc, b.tileMinCoc, cv::NORM_INF), 1e-3) << which;
        EXPECT_LE(cv::norm(a.tileMaxCoc, b.tileMaxCoc, cv::NORM_INF), 1e-3) << which;
        EXPECT_EQ(a.histogram, b.histogram) << which;
        EXPECT_EQ(a.highlightPixels, b.highlightPixels) << which;
        EXPECT_EQ(a.highlightTiles, b.highlightTiles) << which;
        if (!b.tileNeighbourhood.empty()) {
            EXPECT_LE(cv::norm(a.tileNeighbourhood, b.tileNeighbourhood, cv::NORM_RELATIVE | cv::NORM_INF), 1e-5)
                << which;
        }
        const FramePlan& p = pipelines.gpu.plan();
        const FramePlan& q = pipelines.cpu.plan();
        EXPECT_EQ(p.blurTiles, q.blurTiles) << which;
        EXPECT_EQ(p.nearTiles, q.nearTiles) << which;
        EXPECT_EQ(p.highlightSprites, q.highlightSprites) << which;
        EXPECT_EQ(p.blurShift, q.blurShift) << which;
    }
}

class DepthPrepOnGpu : public test::GLTest, public ::testing::WithParamInterface<test::NamedQuality> {};

// Defects caught: any difference of the GPU's depth prep that reaches the frame (the CoC pass
// reading another depth texture than the one filled, a barrier missing between the fill and
// the passes). The frames out are those of the CPU's depth prep, to 8-bit rounding: depths
// that agree to 1e-5 move a CoC by less than 1e-3 px, which flips an 8-bit step at a handful of
// pixels (at most one in a thousand; the planted 2x2 block: 7 %, 19 steps).
TEST_P(DepthPrepOnGpu, FrameOutIsTheCpusOnTheTumClip)
{
    const Frame frame = tumFrame();
    SideBySide pipelines;
    cv::Mat gpu, cpu;
    pipelines.run(frame, tumLens(), GetParam().quality, &gpu, &cpu);
    cv::Mat difference;
    cv::absdiff(gpu, cpu, difference);
    double largest = 0.0;
    cv::minMaxLoc(difference.reshape(1), nullptr, &largest);
    EXPECT_LE(largest, 1.0);
    EXPECT_LE(cv::countNonZero(difference.reshape(1)), static_cast<int>(difference.total() / 1000));
}

// Defects caught: a frame begun ahead overwriting the textures, measurement or settings of the
// frame before it (one set of textures for both, the measurement buffer shared), finish()
// taking the newest frame instead of the oldest, the all-in-focus exit of one frame leaking into
// the next; a frame's GPU timer scopes reported with another frame's (the depth prep and
// measurement of frame N + 1, timed before the passes of N, under N). Frames begun one ahead
// (begin N + 1, finish N, read N: what Filter::submit() does) give the bytes and the timer
// scopes, frame by frame, that one frame at a time gives, with depth prep on the GPU and on the
// CPU. The scopes are timed by glFinish (finishEachPass): names, not times, are compared, and
// llvmpipe's queries now and then report a scope as missing.
TEST_P(DepthPrepOnGpu, FramesBegunAheadGiveTheSerialFrames)
{
    std::vector<Frame> frames = tumFrames(4);
    ASSERT_EQ(frames.size(), 4u);
    frames[2].depth = cv::Mat(frames[2].depth.size(), CV_32F, cv::Scalar(1.0f)); // all in focus at 1 m
    const auto lensOf = [](std::size_t i) {
        LensSettings lens = tumLens();
        lens.focusM = i % 2 == 0 ? 1.0 : 1.5;
        return lens;
    };
    for (const bool onGpu : {true, false}) {
        Pipeline serial, ahead;
        serial.prepareOnGpu(onGpu);
        ahead.prepareOnGpu(onGpu);
        serial.finishEachPass(true);
        ahead.finishEachPass(true);
        // Each frame's scope names, by the frame the timings say they are of.
        using Scopes = std::map<std::size_t, std::string>;
        const auto collect = [](const FrameTimings& timings, Scopes& scopes) {
            if (timings.gpu.empty())
                return;
            std::string& names = scopes[timings.gpuFrame];
            for (const PassTime& time : timings.gpu)
                names += time.name + " ";
        };
        // The last frame's, waited for.
        const auto drain = [&](Pipeline& pipeline, Scopes& scopes) {
            for (const PassTime& time : pipeline.drainGpuTimes())
                scopes[frames.back().index] += time.name + " ";
        };
        std::vector<cv::Mat> expected;
        Scopes expectedScopes, gotScopes;
        for (std::size_t i = 0; i < frames.size(); ++i) {
            expected.push_back(serial.run(frames[i], lensOf(i), GetParam().quality));
            collect(serial.timings(), expectedScopes);
        }
        drain(serial, expectedScopes);
        std::vector<cv::Mat> got;
        for (std::size_t i = 0; i < frames.size(); ++i) {
            ahead.begin(frames[i], lensOf(i), GetParam().quality);
            if (ahead.begun() == 2) {
                ahead.finish();
                got.push_back(ahead.read(View::Composite, Encoding::Srgb8));
                collect(ahead.timings(), gotScopes);
            }
        }
        ahead.finish();
        got.push_back(ahead.read(View::Composite, Encoding::Srgb8));
        collect(ahead.timings(), gotScopes);
        drain(ahead, gotScopes);
        ASSERT_EQ(got.size(), expected.size());
        const char* which = onGpu ? "GPU" : "CPU";
        for (std::size_t i = 0; i < got.size(); ++i)
            EXPECT_EQ(cv::norm(got[i], expected[i], cv::NORM_INF), 0.0) << which << " depth prep, frame " << i;
        // Every blurred frame's scopes (frame 2 is passed through on the adaptive presets).
        for (const std::size_t i : {0, 1, 3}) {
            EXPECT_EQ(expectedScopes.count(frames[i].index), 1u) << which << ", frame " << i;
        }
        EXPECT_EQ(gotScopes, expectedScopes) << which << " depth prep";
    }
}

// Defects caught: 16-bit depth read as metres (its units not divided out), its zeros taken as
// depths instead of holes, the R16UI upload given the wrong format, the units ignored where the
// CPU prepares the depth, the all-in-focus exit reading 16-bit pixels as floats, a GPU conversion
// that rounds otherwise than cv::Mat::convertTo (a division, which GLSL lets be 2.5 ulp off,
// where a product is correctly rounded). The TUM frame's depth in its file's units (5000 a metre)
// gives the frame its metres give, as convertTo makes them, to the byte, on the GPU and on the CPU.
TEST_P(DepthPrepOnGpu, SixteenBitDepthGivesTheFrameItsMetresGive)
{
    constexpr double kUnits = 5000.0;
    Frame units = tumFrame(), metres = units;
    units.depth.convertTo(units.depth, CV_16U, kUnits);
    units.depth.convertTo(metres.depth, CV_32F, 1.0 / kUnits);
    ASSERT_GT(cv::countNonZero(units.depth == 0), 1000) << "the Kinect frame has holes";
    for (const bool onGpu : {true, false}) {
        Pipeline fromUnits, fromMetres;
        fromUnits.prepareOnGpu(onGpu);
        fromMetres.prepareOnGpu(onGpu);
        const char* which = onGpu ? "GPU" : "CPU";
        fromUnits.process(units, tumLens(), GetParam().quality, kUnits);
        fromMetres.process(metres, tumLens(), GetParam().quality);
        EXPECT_EQ(fromUnits.invalidDepthFraction(), fromMetres.invalidDepthFraction()) << which;
        const cv::Mat a = fromUnits.read(View::Composite, Encoding::Srgb8);
        const cv::Mat b = fromMetres.read(View::Composite, Encoding::Srgb8);
        EXPECT_EQ(cv::norm(fromUnits.filledDepth(), fromMetres.filledDepth(), cv::NORM_INF), 0.0) << which;
        EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << which;

        // All in focus at 1 m: decided from the 16-bit range, holes counted as the float's.
        Frame flat = units;
        flat.depth.setTo(static_cast<std::uint16_t>(kUnits), flat.depth != 0);
        Frame flatMetres = metres;
        flatMetres.depth.setTo(1.0f, flatMetres.depth != 0.0f);
        fromUnits.process(flat, tumLens(), GetParam().quality, kUnits);
        fromMetres.process(flatMetres, tumLens(), GetParam().quality);
        if (GetParam().quality.adaptive) {
            EXPECT_TRUE(fromUnits.plan().allInFocus) << which;
        }
        // The exit taken before any depth prep (no tiles analysed) where the metres take it.
        EXPECT_EQ(fromUnits.analysis().tiles, fromMetres.analysis().tiles) << which;
        EXPECT_EQ(fromUnits.invalidDepthFraction(), fromMetres.invalidDepthFraction()) << which;
        EXPECT_EQ(cv::norm(fromUnits.read(View::Composite, Encoding::Srgb8),
                           fromMetres.read(View::Composite, Encoding::Srgb8), cv::NORM_INF),
                  0.0)
            << which;
    }
}

INSTANTIATE_TEST_SUITE_P(Presets, DepthPrepOnGpu, ::testing::ValuesIn(test::presetsAndKernels()),
                         [](const ::testing::TestParamInfo<test::NamedQuality>& p) { return p.param.name; });

} // namespace
} // namespace defocus
