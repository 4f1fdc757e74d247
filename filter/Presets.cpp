// SPDX-License-Identifier: LGPL-2.1-or-later
// The quality presets users choose between, as the pipeline's settings, and why each is what it is.
#include "filter/Presets.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace defocus {

namespace {

/// The rhombi with the foreground spread over what lies behind it, 32-bit float targets, the
/// per-frame plan and the bokeh sprites on, quarter size off: what the three presets share.
QualitySettings rhombiNear(int samples, Resolution resolution)
{
    QualitySettings q;
    q.kernel = HexagonKernel::RhombiSum;
    q.nearField = true;
    q.samples = samples;
    q.resolution = resolution;
    q.targetFormat = TargetFormat::Auto;
    q.adaptive = true;
    q.highlightSprites = true;
    q.quarterOnLargeBlur = false;
    return q;
}

} // namespace

const std::vector<QualityPreset>& qualityPresets()
{
    // Chosen from the Pareto front of `defocus-bench-accuracy --runs 7` (docs/accuracy.md): Blender
    // spheres, 640x480, linear PSNR against the Cycles truth, wall ms per frame (median of 7) on
    // the shared 2-core llvmpipe machine, all in one run (2026-11-24 10:11 UTC, load average 1.7
    // before).
    //
    //   front                     dB      ms      the step to it
    //   lazy8 8        half 32F  26.01    4.4
    //   gaussian5x5    half 32F  27.91    7.2     no hexagon
    //   rhombi 12      half 32F  33.88   18.7     the hexagon at half size, the frame's pixels in focus
    //   rhombi-near 5  half 32F  34.91   20.4     the foreground spread over what is behind it
    //   rhombi-near 6  half 32F  35.14   20.6     (4 taps: 34.85 dB in 20.7 ms, within the noise)
    //   rhombi-near 8  half 32F  35.31   21.0     12-16 taps 35.30 dB
    //   rhombi-near 6  full 32F  35.88   42.2     full size: +0.74 dB over 6 taps at half size for twice the time
    //   rhombi-near 8  full 32F  36.31   50.6
    //   rhombi-near 12 full 32F  36.41   62.4     +0.10 dB for +23 %
    //   rhombi-near 16 full 32F  36.46   67.1     the most accurate setting; the CPU reference: 35.62
    //
    // balanced: half size, where the front's time is nearly flat (the CoC pass, the upscale, the
    // bokeh sprites and the CPU's share are most of the frame, and the taps do not change them);
    // 6 taps, 2.0 dB over the 33 dB target and Blender's Defocus node (32.9 dB in ~1.4 s), in a
    // half of the time of the same kernel at full size. fast: the same at 4 taps, which saves
    // little on llvmpipe (above) but more where the blur passes dominate (a GPU, 4K). high: where
    // the front flattens at full size. McIntosh's chain as published (16 taps, flat top)
    // measures 30.55 dB (tests/AccuracyGLTest, docs/figures.md); the presets all use the rhombi,
    // which keep the hexagon, and a highlight's energy, from preset to preset.
    //
    // The renderer's precision (TargetFormat::Auto): on llvmpipe the full-float targets ran as
    // fast or faster in nearly every row, half floats being converted in software on every fetch
    // and store; on an H100 half floats halved the passes' GPU time (1080p 2.66 -> 1.36 ms). The
    // corpus measured both within 0.02 dB on every scene and preset (docs/benchmarks.md).
    //
    // Quarter size on large blur (QualitySettings::quarterOnLargeBlur) stays off in fast and
    // balanced: at 1920x1080 it took the balanced frame to 0.54 of its time, but on the corpus
    // enlarged 3x (`defocus-bench accuracy --scale 3`, docs/benchmarks.md "Quarter size on large
    // blur") it cost 0.38 dB in the median with sprites and 0.43 dB without, more than the 0.1 dB
    // a preset may lose.
    static const std::vector<QualityPreset> list{
        {"fast", rhombiNear(4, Resolution::Half)},
        {"balanced", rhombiNear(6, Resolution::Half)},
        {"high", rhombiNear(12, Resolution::Full)},
    };
    return list;
}

QualitySettings presetSettings(std::string_view name)
{
    for (const QualityPreset& p : qualityPresets())
        if (p.name == name)
            return p.quality;
    throw std::invalid_argument(
        fmt::format("defocus::preset: no preset called '{}' (choose fast, balanced or high)", name));
}

} // namespace defocus
