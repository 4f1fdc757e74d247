// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-bench timing: for each preset, the frame's wall time (process and readback, as users
// wait for it) and each pass's GPU time, as ratios to a calibration pass measured in the same
// run, written as a baseline or compared with one. Ratios hold on a noisy or different machine
// where milliseconds do not.
//   defocus-bench timing --write-baseline my_baseline.json
//   defocus-bench timing --baseline my_baseline.json --max-ratio 3
// A comparison fails (exit 1) when a preset's frame ratio grows past --max-ratio times the
// baseline's (the passes' ratios are printed beside theirs, to show where the time went), when a preset or pass of the baseline did not run or one ran
// that the baseline does not have (renamed), and when any timed frame was all in focus (the plan
// passes it through: nothing would be timed).
#pragma once

#include <string>
#include <vector>

namespace defocus {

struct TimingOptions {
    std::string data = "data/tum_fr1_rpy"; ///< TUM folder to take frames from
    std::string baseline;                  ///< compare with this file
    std::string writeBaseline;             ///< write the measured ratios here
    /// The presets timed (filter/Presets.hpp); empty: every preset.
    std::vector<std::string> presets;
    int runs = 15;         ///< measured frames per preset (medians over them)
    double maxRatio = 3.0; ///< fail when a preset's frame ratio grows more than this
    double fNumber = 1.4;  ///< lens of the timed frames: 50 mm focused at 1 m
    double maxCocPx = 32.0;
};

/// Returns the exit status (samples/ExitStatus.hpp): 0 within bounds, 1 a failed comparison (the
/// reasons printed) or an input that cannot be read, 75 no GPU timer queries.
int runTimingComparison(const TimingOptions& options);

} // namespace defocus
