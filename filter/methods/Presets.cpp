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
    // the shared 2-core llvmpipe machine, nothing else running (load average 1.0), all in one run.
    //
    //   front                     dB      ms      the step to it
    //   rhombi-near 4  half 32F  30.36   17.1
    //   rhombi-near 6  half 32F  30.62   20.9     +0.26 dB; 8-16 taps within 0.01 dB of it
    //   rhombi 4       full 32F  32.62   48.6     full resolution: in-focus pixels 29.1 -> 48.9 dB
    //   rhombi 6       full 32F  32.91   63.1
    //   rhombi-near 5  full 32F  33.45   63.4     the near field: +0.5 dB for the same time
    //   rhombi-near 6  full 32F  33.91   67.8     +0.46 dB for +7 %
    //   rhombi-near 8  full 32F  34.23   81.5     +0.32 dB for +20 %
    //   rhombi-near 12 full 32F  34.38  107.3     +0.15 dB for +32 %
    //   rhombi-near 16 full 32F  34.42  121.5     the most accurate GPU setting
    //
    // fast: the half-resolution front where it flattens. balanced: the knee over 33 dB (issue
    // 4's target; Blender's Defocus node measures 32.9 dB in ~1.4 s): 5 taps are 0.46 dB worse
    // for 7 % less time, 8 taps 0.32 dB better for 20 % more. high: where the
    // front flattens at full resolution. McIntosh's chain as published (16 taps, flat top)
    // measures 30.27 dB in 129 ms; the presets all use the rhombi, which keep the hexagon, and a
    // highlight's energy, from preset to preset.
    //
    // 32F, not 16F: on llvmpipe the full-float targets ran faster in nearly every row (up to
    // 30 %) at the same accuracy (within 0.01 dB), half floats being converted in software on
    // every fetch and store. On a GPU 16F halves the bandwidth and will likely be the faster;
    // re-measure there.
    static const std::vector<Preset> list{
        {"fast", "rhombi-near", {6, Resolution::Half, TargetFormat::Rgba32F}, 30.62, 20.9},
        {"balanced", "rhombi-near", {6, Resolution::Full, TargetFormat::Rgba32F}, 33.91, 67.8},
        {"high", "rhombi-near", {12, Resolution::Full, TargetFormat::Rgba32F}, 34.38, 107.3},
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
