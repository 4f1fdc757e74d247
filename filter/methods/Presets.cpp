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
    // the shared 2-core llvmpipe machine (load average 3.4 at the start; runs at load 5 measured
    // up to 1.6x slower, so only the ratios carry over).
    //
    //   front (McIntosh)      dB      ms      the step to it
    //   M8  half  32F       27.91    54.0
    //   M12 half  32F       28.56    70.5     +0.65 dB for +31 % (M16 half: thinned taps, 28.20)
    //   M24 half  32F       29.12   128.8
    //   M48 half  32F       29.38   225.1
    //   M12 full  32F       29.88   291.8     full resolution: in-focus pixels 29.1 -> 36.4 dB
    //   M16 full  32F       30.27   312.0     +0.39 dB for +7 % (+22 % in a busier run)
    //   M24 full  32F       30.60   464.5     +0.33 dB for +49 %: past the knee
    //   M32 full  32F       30.75   582.7
    //   M48 full  32F       30.89   772.2     the most accurate GPU setting
    //
    // fast: the cheapest McIntosh point on the front before the half-resolution curve flattens
    // (the 5x5 Gaussian and the lazy gather at half resolution are faster, 27.77 dB in 25 ms and
    // 25.82 dB in 12.5 ms, but lose the hexagon). balanced: the knee of the front at full
    // resolution. high: the most accurate GPU setting; 64 taps measure worse (30.33 dB) because
    // hex_blur.frag thins 64 taps to every 3rd or 9th for small CoCs. No setting reaches issue
    // 4's targets (33 dB at <= 60 ms; 35 dB): the CPU reference shows that 34.6 dB (35.6 with
    // Cycles' pointy-top hexagon) is there for a filter that gets edges, energy and the kernel
    // shape right.
    //
    // 32F, not 16F: on llvmpipe the full-float targets ran faster in nearly every row (up to
    // 20 %) at the same accuracy (within 0.02 dB), half floats being converted in software on
    // every fetch and store. On a GPU 16F halves the bandwidth and will likely be the faster; re-measure there.
    static const std::vector<Preset> list{
        {"fast", "mcintosh", {12, Resolution::Half, TargetFormat::Rgba32F}, 28.56, 70.5},
        {"balanced", "mcintosh", {16, Resolution::Full, TargetFormat::Rgba32F}, 30.27, 312.0},
        {"high", "mcintosh", {48, Resolution::Full, TargetFormat::Rgba32F}, 30.89, 772.2},
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
