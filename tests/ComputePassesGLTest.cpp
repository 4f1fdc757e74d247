// SPDX-License-Identifier: LGPL-2.1-or-later
// The passes' fragment shaders run as compute shaders (Pipeline::computePasses()) against the
// same shaders drawn: one frame out, on every preset and both kernels, the plan on and off.
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "filter/Pipeline.hpp"
#include "filter/gl/Program.hpp"
#include "sources/FrameSource.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

Frame tumFrame()
{
    auto source = openSource({test::dataDir() / "tum_fr1_rpy", std::nullopt, std::nullopt});
    auto frame = source->next();
    EXPECT_TRUE(frame.has_value());
    return frame ? *frame : Frame{};
}

struct Scene {
    std::string name;
    Frame frame;
    LensSettings lens;
};

/// The TUM frame focused near (most of it blurred) and far (a third of the tiles in focus, so
/// the blurs run on tiles and the rest is copied), and railing-lights at its corpus lens.
std::vector<Scene> scenes()
{
    std::vector<Scene> list;
    const Frame tum = tumFrame();
    LensSettings lens;
    lens.fNumber = 1.4;
    lens.maxCocPx = 32.0;
    lens.focusM = 1.0;
    list.push_back({"tum, focus 1 m", tum, lens});
    lens.focusM = 2.5;
    list.push_back({"tum, focus 2.5 m", tum, lens});
    LensSettings railing;
    railing.focusM = 2.0;
    railing.fNumber = 2.0;
    railing.maxCocPx = 48.0;
    list.push_back({"railing-lights", test::railingLights(), railing});
    return list;
}

/// The largest difference of two images of one type, over every channel.
double largest(const cv::Mat& a, const cv::Mat& b)
{
    EXPECT_EQ(a.type(), b.type());
    EXPECT_EQ(a.size(), b.size());
    if (a.type() != b.type() || a.size() != b.size())
        return 1e9;
    cv::Mat difference;
    cv::absdiff(a, b, difference);
    double most = 0.0;
    cv::minMaxLoc(difference.reshape(1), nullptr, &most);
    return most;
}

class ComputePasses : public test::GLTest, public ::testing::WithParamInterface<test::NamedQuality> {};

// Defects caught: a compute form that shades other pixels than the draw (the pixel centre off by
// half a pixel, a uv of another size, the last partial work group skipped or written twice over
// the edge), that stores an output into the wrong image or not at all (pass 1's second line,
// the prefilter's two outputs), that dispatches the wrong tiles (the blur, copy, highlight and
// detail tiles: the blocks of a 16 px tile at full size, one 8 px tile a work group at half),
// or reads a target before the dispatch that writes it is visible (a missing barrier). Linear
// reads are bit-exact: the same shader arithmetic compiled for another stage. 8-bit reads differ
// by at most one step: an sRGB attachment's encoding is the renderer's in a draw and the GL
// spec's formula in a store into its bytes, and the two round the odd value differently.
TEST_P(ComputePasses, FramesOutAreTheDrawnPasses)
{
    Pipeline drawn, computed;
    drawn.computePasses(false);
    computed.computePasses(true);
    for (const Scene& scene : scenes()) {
        ASSERT_FALSE(scene.frame.color.empty()) << scene.name;
        for (const bool adaptive : {true, false}) {
            QualitySettings quality = GetParam().quality;
            quality.adaptive = adaptive;
            const std::string where = scene.name + (adaptive ? ", plan on" : ", plan off");
            const cv::Mat a = drawn.run(scene.frame, scene.lens, quality);
            const cv::Mat b = computed.run(scene.frame, scene.lens, quality);
            ASSERT_FALSE(computed.plan().allInFocus) << where;
            EXPECT_LE(largest(a, b), 1.0) << where;
            EXPECT_EQ(largest(drawn.read(View::Composite, Encoding::Linear32F),
                              computed.read(View::Composite, Encoding::Linear32F)),
                      0.0)
                << where;
            // The targets before the composite: the CoC pass, and the lines or blurs (the rhombi's
            // pass 2 unfused, into two targets).
            for (const View view : {View::Input, View::Horizontal, View::DiagonalA, View::DiagonalB})
                EXPECT_EQ(largest(drawn.readTarget(view), computed.readTarget(view)), 0.0)
                    << where << ", view " << static_cast<int>(view);
        }
    }
}

// Defects caught: the depth prep's compute form storing a pyramid level into the wrong image or
// at the wrong size (a level's size is its own, not the frame's), its uniforms (the target's
// size, the fallback depth, the 16-bit units) set on the drawn program instead of the one that
// runs. The filled depth is bit-exact and the frames the same as above, with depth prep on the
// GPU (the default on a GPU), for 16-bit depth in its units, float depth and the lights' edges.
TEST_P(ComputePasses, DepthPrepOnTheGpuIsTheDrawnPasses)
{
    Pipeline drawn, computed;
    for (Pipeline* pipeline : {&drawn, &computed})
        pipeline->prepareOnGpu(true);
    drawn.computePasses(false);
    computed.computePasses(true);
    for (const Scene& scene : scenes()) {
        if (scene.name == "tum, focus 2.5 m")
            continue;
        Frame frame = scene.frame;
        double units = 0.0;
        if (scene.name == "railing-lights") { // its millimetres as they came
            frame.depth.convertTo(frame.depth, CV_16U, 1000.0);
            units = 1000.0;
        }
        drawn.process(frame, scene.lens, GetParam().quality, units);
        computed.process(frame, scene.lens, GetParam().quality, units);
        const cv::Mat a = drawn.read(View::Composite, Encoding::Linear32F);
        const cv::Mat b = computed.read(View::Composite, Encoding::Linear32F);
        EXPECT_EQ(largest(drawn.filledDepth(), computed.filledDepth()), 0.0) << scene.name;
        EXPECT_EQ(largest(a, b), 0.0) << scene.name;
    }
    // No measured depth at all: the fill puts the frame at the fallback depth (every pass run).
    Frame unmeasured = scenes().front().frame;
    unmeasured.depth.setTo(0.0f);
    QualitySettings everyPass = GetParam().quality;
    everyPass.adaptive = false;
    LensSettings lens = scenes().front().lens;
    lens.focusM = 3.0;
    for (Pipeline* pipeline : {&drawn, &computed})
        pipeline->process(unmeasured, lens, everyPass);
    EXPECT_EQ(largest(drawn.filledDepth(), computed.filledDepth()), 0.0) << "no measured depth";
}

INSTANTIATE_TEST_SUITE_P(Presets, ComputePasses, ::testing::ValuesIn([] {
                             std::vector<test::NamedQuality> list = test::presetsAndKernels();
                             // McIntosh's near field: its own three blurs on the near tiles.
                             QualitySettings near;
                             near.kernel = HexagonKernel::McIntoshMin;
                             near.nearField = true;
                             list.push_back({"mcintosh_near", near});
                             return list;
                         }()),
                         [](const ::testing::TestParamInfo<test::NamedQuality>& p) { return p.param.name; });

// Defects caught: a fragment shader whose interface the compute form would take wrongly (an
// output it does not store, an input other than the uv) built anyway; gl_FragCoord left in
// the compute source; a variant's output declared under its #ifdef but stored unconditionally
// (the fused rhombi have one output, the plain ones two).
TEST(ComputeForm, SourceKeepsEachVariantsOutputs)
{
    const std::string fused = gl::computeFormSource("rhombus_blur.frag", {"FUSED 1", "MAX_TAPS 6"}, false);
    EXPECT_EQ(fused.find("gl_FragCoord"), std::string::npos);
    EXPECT_NE(fused.find("#define COMPUTE_OUTPUT0 outFirst"), std::string::npos);
    EXPECT_NE(fused.find("#define COMPUTE_OUTPUT1 outSecond"), std::string::npos);
    EXPECT_NE(fused.find("void fragmentMain()"), std::string::npos);
    EXPECT_NE(fused.find("#ifdef COMPUTE_OUTPUT1\n    imageStore"), std::string::npos);
    const std::string coc = gl::computeFormSource("coc.frag", {}, true);
    EXPECT_NE(coc.find("#define COMPUTE_TILES 1"), std::string::npos);
    EXPECT_THROW(gl::computeFormSource("highlight_sprite.vert", {}, false), gl::ShaderError);
}

} // namespace
} // namespace defocus
