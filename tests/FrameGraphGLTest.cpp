// SPDX-License-Identifier: LGPL-2.1-or-later
// The pipeline runs the frame graph's nodes: the GPU timer scopes of a frame are the nodes of
// the graph its plan picks, in order, on every preset and both kernels, with and without the
// plan's tile lists, for the composite and for a view read after it.
#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "filter/FrameGraph.hpp"
#include "filter/Pipeline.hpp"
#include "sources/FrameSource.hpp"
#include "sources/ImageIO.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

class FrameGraphRun : public test::GLTest, public ::testing::WithParamInterface<test::NamedQuality> {};

/// The names of `times`, " > " between them.
std::string scopes(const std::vector<PassTime>& times)
{
    std::string text;
    for (const PassTime& time : times)
        text += (text.empty() ? "" : " > ") + time.name;
    return text;
}

/// The pooled images `nodes` write, each once.
std::size_t pooledWrites(const std::vector<Node>& nodes)
{
    std::set<Image> images;
    for (const Node& node : nodes)
        for (const Image image : node.writes)
            if (imageInfo(image).pooled())
                images.insert(image);
    return images.size();
}

GraphChoices choicesOf(const FramePlan& plan, const QualitySettings& quality)
{
    return {quality.kernel, plan.blurShift != 0, plan.nearField, plan.highlightSprites};
}

// Defects caught: a pass the pipeline runs that the graph does not list (or one it lists and the
// pipeline skips), a pass under another name than the graph's, passes run out of the graph's
// order, a plan choice (near field, half size, sprites) that the pipeline follows and the graph
// does not, a target made for an image no node writes, and depth prep on the GPU run otherwise
// than its nodes say (or timed where it runs on the CPU). The 8-bit TUM frame takes the near field and half size of the presets; the
// corpus' float frame with lights above white takes the sprites.
TEST_P(FrameGraphRun, TheTimerScopesAreTheGraphsNodes)
{
    auto source = openSource({test::dataDir() / "tum_fr1_rpy", std::nullopt, std::nullopt});
    const Frame tum = *source->next();
    const auto dir = test::dataDir() / "corpus" / "railing-lights";
    Frame lights;
    lights.color = readColor(dir / "color_linear.exr");
    lights.depth = readDepth(dir / "depth_mm.png", 1000.0);
    LensSettings lens;
    lens.fNumber = 1.4;
    bool sawSprites = false, sawNear = false;
    for (const bool onGpu : {true, false}) {
        Pipeline pipeline;
        pipeline.prepareOnGpu(onGpu);
        for (const bool adaptive : {true, false})
            for (const Frame* frame : std::vector<const Frame*>{&tum, &lights}) {
                QualitySettings quality = GetParam().quality;
                quality.adaptive = adaptive;
                lens.focusM = frame == &tum ? 1.0 : 2.0;
                pipeline.process(*frame, lens, quality);
                pipeline.read(View::Composite, Encoding::Srgb8);
                const std::vector<PassTime> times = pipeline.drainGpuTimes();
                if (times.empty())
                    GTEST_SKIP() << "the driver has no timer queries";
                const FramePlan& plan = pipeline.plan();
                ASSERT_FALSE(plan.allInFocus);
                sawSprites = sawSprites || plan.highlightSprites;
                sawNear = sawNear || plan.nearField;
                const GraphChoices choices = choicesOf(plan, quality);
                const std::vector<Node> composite = compositeFrame(choices);
                const bool lightEdges = frame->color.type() == CV_32FC3 && quality.kernel == HexagonKernel::RhombiSum &&
                                        quality.highlightSprites;
                std::vector<Node> prepared = prepareNodes(onGpu, lightEdges);
                prepared.insert(prepared.end(), composite.begin(), composite.end());
                EXPECT_EQ(scopes(times), describe(prepared))
                    << GetParam().name << ", adaptive " << adaptive << (onGpu ? ", GPU" : ", CPU") << " depth prep";
                // A target for each image the nodes wrote, and none for one they did not (the rhombi's
                // A and B, which the fused composite never reads; the sprites' buffer).
                EXPECT_EQ(pipeline.targetsHeld(), pooledWrites(composite)) << GetParam().name;

                // A view of diagonal B after the composite: the rhombi's second pass into A and B.
                std::vector<bool> written(kImageCount, false);
                for (const Node& node : composite)
                    for (const Image image : node.writes)
                        written[static_cast<std::size_t>(image)] = true;
                pipeline.read(View::DiagonalB, Encoding::Srgb8);
                const std::vector<Node> view = viewNodes(choices, View::DiagonalB, written);
                EXPECT_EQ(scopes(pipeline.drainGpuTimes()), describe(view)) << GetParam().name;
                std::vector<Node> both = composite;
                both.insert(both.end(), view.begin(), view.end());
                EXPECT_EQ(pipeline.targetsHeld(), pooledWrites(both)) << GetParam().name;
            }
    }
    // The presets use both; the kernels' plain settings have no near field, and McIntosh's
    // blurs no sprites.
    if (GetParam().quality.nearField) {
        EXPECT_TRUE(sawNear);
    }
    if (GetParam().quality.highlightSprites && GetParam().quality.kernel == HexagonKernel::RhombiSum) {
        EXPECT_TRUE(sawSprites);
    }
}

INSTANTIATE_TEST_SUITE_P(PresetsAndKernels, FrameGraphRun, ::testing::ValuesIn(test::presetsAndKernels()),
                         [](const ::testing::TestParamInfo<test::NamedQuality>& p) { return p.param.name; });

} // namespace
} // namespace defocus
