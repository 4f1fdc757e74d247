// End to end on the recorded TUM clip: every pair found, frames out = frames in, every target
// finite, in-focus pixels unchanged, strongly blurred pixels changed.
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "filter/Pipeline.hpp"
#include "sinks/FrameSink.hpp"
#include "sources/FrameSource.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

class PipelineTum : public test::GLTest {};

TEST_F(PipelineTum, RecordedClipEndToEnd)
{
    auto source = openSource({test::dataDir() / "tum_fr1_rpy", std::nullopt, std::nullopt});
    ASSERT_EQ(source->frameCount(), std::optional<std::size_t>(10));
    const auto outDir = test::scratchDir("pipeline_tum");
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
        const cv::Mat out = pipeline.run(*frame, lens, {});
        sink->write(out);
        EXPECT_GT(pipeline.invalidDepthFraction(), 0.0) << "the Kinect clip has holes";

        for (const View target : {View::Input, View::Horizontal, View::DiagonalA, View::DiagonalB})
            EXPECT_TRUE(test::allFinite(pipeline.readTarget(target))) << frame->name << " " << viewName(target);

        std::vector<cv::Mat> coc;
        cv::split(pipeline.readTarget(View::Input), coc);
        const cv::Mat absCoc = cv::abs(coc[3]);
        cv::Mat diff;
        cv::absdiff(out, frame->color, diff);
        diff = diff.reshape(1, diff.rows * diff.cols).clone();
        cv::Mat maxDiff;
        cv::reduce(diff, maxDiff, 1, cv::REDUCE_MAX);
        maxDiff = maxDiff.reshape(1, out.rows);

        // In focus (CoC under half a pixel): unchanged but for the half-float round trip, which
        // can move a value by one 8-bit step; the issue allows two.
        const cv::Mat sharp = absCoc < 0.5f;
        ASSERT_GT(cv::countNonZero(sharp), 1000) << frame->name << ": focus 1 m must have pixels in focus";
        double worst = 0;
        cv::minMaxLoc(maxDiff, nullptr, &worst, nullptr, nullptr, sharp);
        EXPECT_LE(worst, 2.0) << frame->name;

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

} // namespace
} // namespace defocus
