// SPDX-License-Identifier: LGPL-2.1-or-later
// End to end on the recorded TUM clip with each preset: every pair found, frames out = frames in,
// every target finite, in-focus pixels unchanged, strongly blurred pixels changed.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "filter/Lens.hpp"
#include "filter/Pipeline.hpp"
#include "filter/SceneAnalysis.hpp"
#include "sinks/FrameSink.hpp"
#include "sources/FrameSource.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

// Each shipped preset (balanced, the default, first), as the CLI runs them.
class PipelineTum : public test::GLTest, public ::testing::WithParamInterface<test::NamedQuality> {};

TEST_P(PipelineTum, RecordedClipEndToEnd)
{
    const QualitySettings quality = GetParam().quality;
    auto source = openSource({test::dataDir() / "tum_fr1_rpy", std::nullopt, std::nullopt});
    ASSERT_EQ(source->frameCount(), std::optional<std::size_t>(10));
    const auto outDir = test::scratchDir("pipeline_tum_" + GetParam().name);
    auto sink = openSink({outDir / "frames/", 30.0, false});

    LensSettings lens;
    lens.focusM = 1.0;
    lens.fNumber = 1.4;
    lens.maxCocPx = 32.0;
    Pipeline pipeline;
    std::size_t framesIn = 0;
    while (auto frame = source->next()) {
        ++framesIn;
        ASSERT_FALSE(frame->depth.empty()) << frame->name << ": its depth pair was not found";
        const cv::Mat out = pipeline.run(*frame, lens, quality);
        sink->write(out);
        ASSERT_EQ(out.size(), frame->color.size());
        EXPECT_GT(pipeline.invalidDepthFraction(), 0.0) << "the Kinect clip has holes";

        for (const View target : {View::Input, View::Horizontal, View::DiagonalA, View::DiagonalB})
            EXPECT_TRUE(test::allFinite(pipeline.readTarget(target))) << frame->name << " " << viewName(target);

        // The CoC of each of the frame's pixels (the targets are half size at half resolution).
        const CocCoefficients k = cocCoefficients(lens, out.cols);
        const cv::Mat& depth = pipeline.filledDepth();
        cv::Mat absCoc(depth.size(), CV_32F);
        for (int y = 0; y < depth.rows; ++y)
            for (int x = 0; x < depth.cols; ++x)
                absCoc.at<float>(y, x) = std::abs(cocPixels(k, depth.at<float>(y, x)));
        cv::Mat diff;
        cv::absdiff(out, frame->color, diff);
        diff = diff.reshape(1, diff.rows * diff.cols).clone();
        cv::Mat maxDiff;
        cv::reduce(diff, maxDiff, 1, cv::REDUCE_MAX);
        maxDiff = maxDiff.reshape(1, out.rows);

        // In focus (CoC under half a pixel), two pixels or more from any blurred pixel (at half
        // size the upscale interpolates what the blur added, which reaches a pixel's neighbours)
        // and beyond the reach of blurred foreground (the near field spreads a near pixel over
        // what lies behind it within its radius |CoC| / 2, by design; a pixel more for the
        // bilinear taps, two more for the upscale): unchanged, to the bit. The passes copy such
        // pixels, the upscale puts the frame's own pixel back, and RGBA32F (every preset's)
        // rounds an 8-bit value back to itself. Defect caught: a sharp pixel moved by any step.
        cv::Mat sharp = absCoc < 0.5f;
        cv::erode(sharp, sharp, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
        if (quality.nearField) {
            cv::Mat signedCoc(depth.size(), CV_32F);
            for (int y = 0; y < depth.rows; ++y)
                for (int x = 0; x < depth.cols; ++x)
                    signedCoc.at<float>(y, x) = cocPixels(k, depth.at<float>(y, x));
            sharp.setTo(0, test::foregroundReach(signedCoc, 3));
        }
        ASSERT_GT(cv::countNonZero(sharp), 1000) << frame->name << ": focus 1 m must have pixels in focus";
        double worst = 0;
        cv::minMaxLoc(maxDiff, nullptr, &worst, nullptr, nullptr, sharp);
        EXPECT_EQ(worst, 0.0) << frame->name;

        // Strong blur (CoC over 12 px): most such pixels visibly changed. Flat regions (white
        // desk) can stay the same under any blur, so ask for a majority, not all.
        const cv::Mat blurry = absCoc > 12.0f;
        const int blurryCount = cv::countNonZero(blurry);
        ASSERT_GT(blurryCount, 1000) << frame->name;
        const int changed = cv::countNonZero((maxDiff > 2) & blurry);
        EXPECT_GT(changed, blurryCount / 2) << frame->name;
    }
    sink->finish();
    EXPECT_EQ(framesIn, 10u);
    EXPECT_EQ(sink->framesWritten(), framesIn);
    std::size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(outDir / "frames"))
        files += entry.path().extension() == ".png" ? 1 : 0;
    EXPECT_EQ(files, framesIn);
}

INSTANTIATE_TEST_SUITE_P(Presets, PipelineTum, ::testing::ValuesIn(test::shippedPresets()),
                         [](const ::testing::TestParamInfo<test::NamedQuality>& p) { return p.param.name; });

} // namespace
} // namespace defocus
