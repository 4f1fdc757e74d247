// SPDX-License-Identifier: LGPL-2.1-or-later
// Plan against always-on: the same frames through one pipeline with QualitySettings::adaptive
// on and off, interleaved pass by pass so that the machine's drift spreads over both.
#include "bench/BenchPlan.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "filter/Pipeline.hpp"
#include "filter/Presets.hpp"
#include "filter/gl/EglContext.hpp"
#include "samples/BenchMachine.hpp"
#include "sources/FrameSource.hpp"
#include "sources/SyntheticSource.hpp"

#include "samples/ExitStatus.hpp"

namespace defocus {

namespace {

struct Clip {
    std::string name;
    std::vector<Frame> frames;
    std::vector<LensSettings> lenses; ///< one per frame
};

Clip tumClip(const std::string& folder, double fNumber)
{
    Clip clip{fmt::format("TUM f/{:g}", fNumber), {}, {}};
    auto source = openSource({folder, std::nullopt, std::nullopt});
    LensSettings lens; // defocus-bench's lens: 50 mm focused at 1 m, max-coc 32 px
    lens.focusM = 1.0;
    lens.fNumber = fNumber;
    while (auto frame = source->next()) {
        clip.frames.push_back(std::move(*frame));
        clip.lenses.push_back(lens);
    }
    return clip;
}

Clip syntheticClip(const std::string& scene, int frames)
{
    Clip clip{fmt::format("synthetic {}", scene), {}, {}};
    SyntheticSettings settings; // defocus --demo's: its focus pull, the default lens
    settings.frames = static_cast<std::size_t>(frames);
    SyntheticSource source(syntheticScene(scene), settings);
    while (auto frame = source.next()) {
        clip.lenses.push_back(source.lensAt(frame->index));
        clip.frames.push_back(std::move(*frame));
    }
    return clip;
}

} // namespace

int runPlanComparison(const PlanOptions& options)
{
    if (!std::filesystem::is_directory(options.data)) {
        std::fprintf(stderr, "defocus-bench plan: data '%s' not found (run from the repository root or pass --data)\n",
                     options.data.c_str());
        return kExitBadInput;
    }
    auto context = gl::EglContext::create();
    std::vector<Clip> clips;
    clips.push_back(tumClip(options.data, 2.0));
    clips.push_back(tumClip(options.data, 22.0));
    clips.push_back(syntheticClip("spheres", options.syntheticFrames));
    clips.push_back(syntheticClip("edges", options.syntheticFrames));

    const QualitySettings base = presetSettings(options.preset);
    Pipeline pipeline;
    std::printf("defocus-bench plan: --quality %s (%s size, %d taps), %d passes per mode, interleaved; %s\n",
                options.preset.c_str(), std::string(resolutionName(base.resolution)).c_str(), base.samples,
                options.passes, context.info().glRenderer.c_str());
    std::printf("%-18s %6s %6s %10s %10s %6s %10s %12s %12s\n", "clip", "in", "out", "plan ms", "always ms", "ratio",
                "identical", "lowest dB", "tiles blurred");
    for (const Clip& clip : clips) {
        std::vector<double> ms[2];
        std::vector<cv::Mat> out[2];
        double tiles = 0.0;
        for (int pass = 0; pass <= options.passes; ++pass) // pass 0 warms up, untimed
            for (const int mode : {0, 1}) {
                QualitySettings quality = base;
                quality.adaptive = mode == 0;
                out[mode].clear();
                for (std::size_t i = 0; i < clip.frames.size(); ++i) {
                    const auto start = std::chrono::steady_clock::now();
                    out[mode].push_back(pipeline.run(clip.frames[i], clip.lenses[i], quality));
                    const double elapsed =
                        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
                    if (pass > 0)
                        ms[mode].push_back(elapsed);
                    if (pass == 1 && mode == 0)
                        tiles += pipeline.plan().allInFocus ? 0.0 : static_cast<double>(pipeline.plan().blurTiles.size());
                }
            }
        int identical = 0;
        double lowest = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < clip.frames.size(); ++i) {
            const double differing = cv::norm(out[0][i], out[1][i], cv::NORM_INF);
            if (differing == 0.0)
                ++identical;
            else
                lowest = std::min(lowest, cv::PSNR(out[0][i], out[1][i]));
        }
        const double plan = median(ms[0]), always = median(ms[1]);
        std::printf("%-18s %6zu %6zu %10.1f %10.1f %6.2f %7d/%-2zu %12s %12.0f\n", clip.name.c_str(),
                    clip.frames.size(), out[0].size(), plan, always, plan / always, identical, clip.frames.size(),
                    std::isinf(lowest) ? "-" : fmt::format("{:.1f}", lowest).c_str(),
                    tiles / static_cast<double>(clip.frames.size()));
    }
    std::printf("ratio = plan / always-on (medians of every frame of every pass); identical = frames whose 8-bit "
                "outputs match to the bit; lowest dB = the smallest PSNR between the two outputs of a frame that "
                "differs; tiles blurred = mean per frame under the plan (of the frame's 16x16 tiles)\n");
    return 0;
}

} // namespace defocus
