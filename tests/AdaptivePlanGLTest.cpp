// SPDX-License-Identifier: LGPL-2.1-or-later
// The per-frame plan (QualitySettings::adaptive: all-in-focus frames passed through, in-focus
// tiles copied, tap loops cut to the frame's lines, upscale detail only where needed) is claimed
// to cost nothing in the picture: the same clips rendered with the plan and with every pass on
// every pixel must give the same 8-bit output, to the bit, on every preset and on McIntosh's
// chain.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "filter/Pipeline.hpp"
#include "sources/FrameSource.hpp"
#include "sources/SyntheticSource.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

class AdaptivePlan : public test::GLTest {};

struct Clip {
    std::string name;
    std::vector<Frame> frames;
    std::vector<LensSettings> lenses; ///< one per frame
};

/// Frames 0, 4 and 9 of the bundled TUM clip (640x480, 8-bit), each under every lens of `lenses`.
Clip tumClip(const std::vector<std::pair<std::string, LensSettings>>& lenses)
{
    Clip clip{"TUM", {}, {}};
    auto source = openSource({test::dataDir() / "tum_fr1_rpy", std::nullopt, std::nullopt});
    std::size_t index = 0;
    while (auto frame = source->next()) {
        if (index == 0 || index == 4 || index == 9)
            for (const auto& [name, lens] : lenses) {
                Frame copy = *frame;
                copy.name += " " + name;
                clip.frames.push_back(copy);
                clip.lenses.push_back(lens);
            }
        ++index;
    }
    return clip;
}

/// A synthetic scene (float HDR colour, planar depth) at 320x240, its focus pull over 4 frames.
Clip syntheticClip(const std::string& scene)
{
    Clip clip{"synthetic " + scene, {}, {}};
    SyntheticSettings settings;
    settings.width = 320;
    settings.height = 240;
    settings.frames = 4;
    settings.lens.fNumber = 1.4;
    SyntheticSource source(syntheticScene(scene), settings);
    while (auto frame = source.next()) {
        clip.lenses.push_back(source.lensAt(frame->index));
        clip.frames.push_back(std::move(*frame));
    }
    return clip;
}

// Defects caught: a plan that skips work a pixel needs. An all-in-focus threshold set too high
// (a frame whose largest CoC is 0.8 px passed through unblurred, where McIntosh's chain blurs it;
// one of 1.6 px, where the rhombi do), a tile copied that needed its blur, tap loops cut short of
// a line's end, upscale detail left out of a tile that had pixels under 2 px of CoC. The lenses
// on the TUM clip (50 mm, focused at 1 m): f/2 (most tiles blurred), f/22 (about a third: the
// tiled paths), and the largest CoC clamped to 0.8 px, 1.6 px and 0.4 px (the frame all in
// focus: the plan passes it through, the passes copy every pixel). Targets are RGBA32F, as the
// presets': with half floats the passes round an unblurred pixel by up to one 8-bit step
// (PassesGLTest ZeroCocReturnsTheInput), which the plan's pass-through does not.
TEST_F(AdaptivePlan, IsBitIdenticalToEveryPassOnEveryPixel)
{
    std::vector<std::pair<std::string, LensSettings>> lenses;
    for (const double fNumber : {2.0, 22.0}) {
        LensSettings lens;
        lens.focusM = 1.0;
        lens.fNumber = fNumber;
        lenses.push_back({"f/" + std::to_string(static_cast<int>(fNumber)), lens});
    }
    for (const double maxCoc : {0.8, 1.6, 0.4}) {
        LensSettings lens;
        lens.focusM = 1.0;
        lens.fNumber = 1.4;
        lens.maxCocPx = maxCoc;
        lenses.push_back({"max-coc " + std::to_string(maxCoc), lens});
    }
    const std::vector<Clip> clips{tumClip(lenses), syntheticClip("spheres"), syntheticClip("edges")};

    std::vector<test::NamedQuality> qualities = test::shippedPresets();
    for (auto q : test::presetsAndKernels())
        if (q.name == "mcintosh") {
            q.quality.targetFormat = TargetFormat::Rgba32F;
            qualities.push_back(q);
        }

    Pipeline pipeline(false);
    int allInFocus = 0, tiled = 0;
    for (const auto& [name, base] : qualities)
        for (const Clip& clip : clips)
            for (std::size_t i = 0; i < clip.frames.size(); ++i) {
                QualitySettings quality = base;
                quality.adaptive = true;
                const cv::Mat planned = pipeline.run(clip.frames[i], clip.lenses[i], quality);
                const FramePlan plan = pipeline.plan();
                allInFocus += plan.allInFocus ? 1 : 0;
                tiled += !plan.allInFocus && !plan.copyTiles.empty() ? 1 : 0;
                quality.adaptive = false;
                const cv::Mat always = pipeline.run(clip.frames[i], clip.lenses[i], quality);
                EXPECT_EQ(cv::norm(planned, always, cv::NORM_INF), 0.0)
                    << name << ", " << clip.name << ", " << clip.frames[i].name << ": "
                    << (plan.allInFocus ? "passed through as all in focus"
                                        : plan.explain(pipeline.analysis()));
            }
    // The clips exercise what the plan skips: whole frames and tiles.
    EXPECT_GT(allInFocus, 0);
    EXPECT_GT(tiled, 0);
}

} // namespace
} // namespace defocus
