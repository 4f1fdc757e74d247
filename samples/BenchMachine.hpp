// What the benchmark programs record about the run: when, and on which CPU.
#pragma once

#include <string>

namespace defocus {

/// The current time, UTC, ISO 8601 ("2026-11-22T02:04:48Z").
std::string utcNow();
/// The CPU's model name from /proc/cpuinfo; "unknown" when it cannot be read.
std::string cpuModel();

} // namespace defocus
