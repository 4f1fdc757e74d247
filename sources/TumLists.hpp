// SPDX-License-Identifier: LGPL-2.1-or-later
// Parsers for the TUM RGB-D list files (rgb.txt, depth.txt, associations.txt) and the pairing of
// colour with depth by timestamp: pure functions on text, used by TumSource and the fuzzers.
#pragma once

#include <cstddef>
#include <filesystem>
#include <istream>
#include <optional>
#include <vector>

namespace defocus::tum {

/// One "timestamp filename" entry of rgb.txt or depth.txt.
struct Listed {
    double time = 0.0;           ///< seconds, finite
    std::filesystem::path file;  ///< relative to the sequence folder, as listed
    std::size_t line = 0;        ///< from 1
};

/// One "rgb_time rgb_file depth_time depth_file" line of associations.txt.
struct Association {
    Listed rgb;
    Listed depth;
};

/// Parses rgb.txt or depth.txt: lines of "timestamp file"; blank lines and lines whose first word
/// starts with '#' are skipped; a trailing CR is ignored. `name` is the list's path, for messages.
/// Throws SourceError "NAME:LINE: expected 'timestamp file', got '...'" on the first bad line.
std::vector<Listed> parseTimestampList(std::istream& in, const std::filesystem::path& name);

/// Parses associations.txt (as written by the benchmark's associate.py), with the same rules.
std::vector<Association> parseAssociations(std::istream& in, const std::filesystem::path& name);

/// For each colour entry, the index into `depth` of the depth entry nearest in time (ties go to
/// the earlier one), or nullopt when none lies within `maxGap` seconds (plus 1 us for the six
/// printed decimals). `depth` need not be sorted.
std::vector<std::optional<std::size_t>> pairByTimestamp(const std::vector<Listed>& rgb,
                                                        const std::vector<Listed>& depth, double maxGap);

/// Frame rate in Hz from capture times (any order; non-finite ones are ignored): the mean over frame intervals, leaving out
/// dropped frames (intervals of 1.5 median intervals or more). 30 when there are fewer than two
/// distinct times or the estimate falls outside [kMinFrameRate, kMaxFrameRate].
double estimateFrameRate(std::vector<double> times);

inline constexpr double kMinFrameRate = 0.1;
inline constexpr double kMaxFrameRate = 1000.0;

} // namespace defocus::tum
