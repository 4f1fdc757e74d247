// defocus-bench timing: per-pass GPU time as a ratio to a calibration pass measured in the same
// run, written as a baseline or compared with one. Ratios hold on a noisy or different machine
// where milliseconds do not.
//   defocus-bench timing --write-baseline my_baseline.json
//   defocus-bench timing --baseline my_baseline.json --max-ratio 3
#pragma once

#include <string>

namespace defocus {

struct TimingOptions {
    std::string data = "data/tum_fr1_rpy"; ///< TUM folder to take frames from
    std::string baseline;                  ///< compare with this file
    std::string writeBaseline;             ///< write the measured ratios here
    std::string preset = "balanced";       ///< the quality preset timed (filter/methods/Presets.hpp)
    int runs = 15;                         ///< measured frames (medians over them)
    double maxRatio = 3.0;                 ///< fail when a pass's ratio grows more than this
};

/// Returns the process exit code: 0 within bounds, 1 regression, 2 bad input.
int runTimingComparison(const TimingOptions& options);

} // namespace defocus
