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
    // the shared 2-core llvmpipe machine, all in one run (2026-11-22, load average 0.8 before).
    //
    //   front                     dB      ms      the step to it
    //   lazy8 8        half 32F  25.82    8.5
    //   gaussian5x5    half 32F  27.77   14.0     no hexagon
    //   rhombi-near 4  half 32F  32.82   26.8     the hexagon at half size, the frame's pixels in focus
    //   rhombi-near 6  half 32F  33.05   28.6     +0.23 dB for +7 %
    //   rhombi-near 8  half 32F  33.13   31.7     +0.08 dB for +11 %; 12-16 taps 33.14 dB
    //   rhombi-near 5  full 32F  33.45   60.2     full size: +0.40 dB over 6 taps at half size for twice the time
    //   rhombi-near 6  full 32F  33.91   68.0
    //   rhombi-near 8  full 32F  34.23   83.9
    //   rhombi-near 12 full 32F  34.38  113.5     +0.15 dB for +35 %
    //   rhombi-near 16 full 32F  34.42  121.8     the most accurate GPU setting
    //
    // balanced: the fastest setting over 33 dB (issue 4's target; Blender's Defocus node measures
    // 32.9 dB in ~1.4 s), in 42 % of the time of the same kernel at full size. fast: the same at 4
    // taps (at half size most of the frame is the CoC pass, the upscale and the CPU's share, which
    // the taps do not change). high: where the front flattens at full size. McIntosh's chain as
    // published (16 taps, flat top) measured 30.27 dB; the presets all use the rhombi, which keep
    // the hexagon, and a highlight's energy, from preset to preset.
    //
    // 32F, not 16F: on llvmpipe the full-float targets ran as fast or faster in nearly every row
    // at the same accuracy (within 0.01 dB), half floats being converted in software on every
    // fetch and store. On a GPU 16F halves the bandwidth and will likely be the faster;
    // re-measure there.
    static const std::vector<Preset> list{
        {"fast", "rhombi-near", {4, Resolution::Half, TargetFormat::Rgba32F}, 32.82, 26.8},
        {"balanced", "rhombi-near", {6, Resolution::Half, TargetFormat::Rgba32F}, 33.05, 28.6},
        {"high", "rhombi-near", {12, Resolution::Full, TargetFormat::Rgba32F}, 34.38, 113.5},
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
