// SPDX-License-Identifier: LGPL-2.1-or-later
// The quality presets (fast, balanced, high: the public defocus::Quality::Preset) as the
// pipeline's settings. They were chosen from the Pareto front of the accuracy benchmark
// (docs/accuracy.md has the table and the command that measures it); the benchmark states each as
// one of its methods, with the figures it recorded, in bench/methods/Presets.hpp.
#pragma once

#include <string_view>
#include <vector>

#include "filter/Settings.hpp"

namespace defocus {

struct QualityPreset {
    std::string_view name;   ///< "fast", "balanced", "high"
    QualitySettings quality; ///< kernel, near field, samples, resolution, precision, plan, sprites
};

/// fast, balanced, high, in that order.
const std::vector<QualityPreset>& qualityPresets();
/// The QualitySettings of preset `name` for defocus::Pipeline. Throws std::invalid_argument
/// naming the choices for an unknown name.
QualitySettings presetSettings(std::string_view name);

inline constexpr std::string_view kDefaultPreset = "balanced";

} // namespace defocus
