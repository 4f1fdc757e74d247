// The quality presets (fast, balanced, high), chosen from the Pareto front of the accuracy
// benchmark; docs/accuracy.md has the table they come from and the command that measures it.
#pragma once

#include <string_view>
#include <vector>

#include "filter/Settings.hpp"
#include "filter/methods/Method.hpp"

namespace defocus {

struct Preset {
    std::string_view name;   ///< "fast", "balanced", "high"
    std::string_view method; ///< registry name, e.g. "mcintosh"
    MethodSettings settings;
    /// What it measured on the Blender scene at 640x480 on the 2-core llvmpipe machine
    /// (docs/accuracy.md): linear PSNR clipped to [0, 1], dB, and wall ms per frame (median).
    double psnrDb = 0.0;
    double msPerFrame = 0.0;
};

/// fast, balanced, high, in that order.
const std::vector<Preset>& presets();
/// The preset called `name`; throws std::invalid_argument naming the choices for another name.
const Preset& preset(std::string_view name);
/// The QualitySettings of preset `name` for defocus::Pipeline (kernel, near field, samples,
/// resolution, precision). Throws std::invalid_argument for an unknown name.
QualitySettings presetSettings(std::string_view name);

inline constexpr std::string_view kDefaultPreset = "balanced";

} // namespace defocus
