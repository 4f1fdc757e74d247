// SPDX-License-Identifier: LGPL-2.1-or-later
// The product's quality presets (filter/Presets.hpp) as methods of the benchmark's registry, with
// the figures the accuracy benchmark recorded for each (docs/accuracy.md has the table they were
// chosen from and the command that measures it).
#pragma once

#include <string_view>
#include <vector>

#include "bench/methods/Method.hpp"

namespace defocus {

struct Preset {
    std::string_view name;   ///< "fast", "balanced", "high"
    std::string_view method; ///< registry name, e.g. "rhombi-near"
    MethodSettings settings;
    /// What it measured on the Blender scene at 640x480 on the 2-core llvmpipe machine
    /// (docs/accuracy.md): linear PSNR clipped to [0, 1], dB, and wall ms per frame (median).
    double psnrDb = 0.0;
    double msPerFrame = 0.0;
};

/// fast, balanced, high, in that order. Each runs exactly the product's presetSettings(name): a
/// product preset the registry cannot state throws std::logic_error here.
const std::vector<Preset>& presets();
/// The preset called `name`; throws std::invalid_argument naming the choices for another name.
const Preset& preset(std::string_view name);

} // namespace defocus
