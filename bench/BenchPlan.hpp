// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-bench plan: the per-frame plan against every pass on every pixel ("measure
// and record"), on the TUM clip at an open and a closed aperture and on the synthetic clips:
// ms per frame of each, frames in and out, and how far apart their outputs are.
//   defocus-bench plan                      (from the repository root; about a minute)
//   defocus-bench plan --quality high --passes 5
#pragma once

#include <string>

namespace defocus {

struct PlanOptions {
    std::string data = "data/tum_fr1_rpy"; ///< TUM folder
    std::string preset = "balanced";       ///< quality preset (filter/Presets.hpp)
    int passes = 3;                        ///< timed passes over each clip, per mode, interleaved
    int syntheticFrames = 12;              ///< frames of each synthetic clip
};

/// Prints the comparison; returns the process exit code (0, or 2 for bad input).
int runPlanComparison(const PlanOptions& options);

} // namespace defocus
