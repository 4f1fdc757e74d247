// The presets and the figures they were chosen by.
#include "filter/methods/Presets.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "filter/methods/PipelineMethod.hpp"

namespace defocus {

const std::vector<Preset>& presets()
{
    // Chosen from the Pareto front of `defocus-bench-accuracy --runs 7` (docs/accuracy.md): Blender
    // spheres, 640x480, linear PSNR against the Cycles truth, wall ms per frame (median of 7) on
    // the shared 2-core llvmpipe machine, all in one run (2026-11-22, load average 1.2 before;
    // the machine ran 25 % slower that day than on 2026-11-15, when rhombi-near 6 full took
    // 67.8 ms against 85.0 here: compare rows, not days).
    //
    //   front                     dB      ms      the step to it
    //   lazy8 8        half 32F  25.82   12.7
    //   gaussian5x5    half 32F  27.77   17.9     no hexagon
    //   rhombi-near 4  half 32F  32.73   37.3     the hexagon at half size, the frame's pixels in focus
    //   rhombi-near 6  half 32F  33.10   41.0     +0.37 dB for +10 %; 8-16 taps 33.20 dB
    //   rhombi-near 5  full 32F  33.45   78.8     full size: +0.35 dB for twice the time
    //   rhombi-near 6  full 32F  33.91   85.0
    //   rhombi-near 8  full 32F  34.23  106.5
    //   rhombi-near 12 full 32F  34.38  151.3     +0.15 dB for +42 %
    //   rhombi-near 16 full 32F  34.42  153.6     the most accurate GPU setting
    //
    // balanced: the fastest setting over 33 dB (issue 4's target; Blender's Defocus node measures
    // 32.9 dB in ~1.4 s), at half the time of the full-size one. fast: the same at 4 taps, 0.37 dB
    // for 10 % less time (at half size most of the frame is the CoC pass, the upscale and the
    // CPU's share, which the taps do not change). high: where the front flattens at full size.
    // McIntosh's chain as published (16 taps, flat top) measured 30.27 dB; the presets all use
    // the rhombi, which keep the hexagon, and a highlight's energy, from preset to preset.
    //
    // 32F, not 16F: on llvmpipe the full-float targets ran as fast or faster in nearly every row
    // at the same accuracy (within 0.01 dB), half floats being converted in software on every
    // fetch and store. On a GPU 16F halves the bandwidth and will likely be the faster;
    // re-measure there.
    static const std::vector<Preset> list{
        {"fast", "rhombi-near", {4, Resolution::Half, TargetFormat::Rgba32F}, 32.73, 37.3},
        {"balanced", "rhombi-near", {6, Resolution::Half, TargetFormat::Rgba32F}, 33.10, 41.0},
        {"high", "rhombi-near", {12, Resolution::Full, TargetFormat::Rgba32F}, 34.38, 151.3},
    };
    return list;
}

const Preset& preset(std::string_view name)
{
    for (const Preset& p : presets())
        if (p.name == name)
            return p;
    throw std::invalid_argument(
        fmt::format("defocus::preset: no preset called '{}' (choose fast, balanced or high)", name));
}

QualitySettings presetSettings(std::string_view name)
{
    const Preset& p = preset(name);
    return PipelineMethod::quality(p.method, p.settings);
}

} // namespace defocus
