// SPDX-License-Identifier: LGPL-2.1-or-later
// What the benchmark programs and the batch reports share: when and on which CPU a run was made,
// and the statistics they report (median and p90 with linear interpolation between order
// statistics).
#pragma once

#include <string>
#include <vector>

namespace defocus {

/// The current time, UTC, ISO 8601 ("2026-11-22T02:04:48Z").
std::string utcNow();
/// The CPU's model name from /proc/cpuinfo; "unknown" when it cannot be read.
std::string cpuModel();

/// q-quantile with linear interpolation between order statistics (numpy's default); NaN when
/// `values` is empty.
double quantile(std::vector<double> values, double q);
double median(const std::vector<double>& values); ///< quantile(values, 0.5)
double p90(const std::vector<double>& values);    ///< quantile(values, 0.9)

} // namespace defocus
