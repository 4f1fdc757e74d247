// Helpers shared by the tests: where the bundled data lives, scratch folders, image statistics.
#pragma once

#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

#include "filter/Settings.hpp"

namespace defocus::test {

/// The repository's data/ folder (bundled fixtures).
std::filesystem::path dataDir();
/// A fresh, empty folder under the build tree for one test's files.
std::filesystem::path scratchDir(const std::string& name);

struct CliResult {
    int exitCode = -1;
    std::string output; ///< stdout and stderr
};
/// Runs the built `defocus` with `arguments` (already quoted for the shell) and waits for it;
/// a missing binary fails the calling test.
CliResult runDefocus(const std::string& arguments);
/// A lens whose CoC at 2 m depth is exactly `diameterPx`: the focal-range model focused at 1 m,
/// blur reaching max-coc at the far limit, 2 m.
LensSettings lensWithFarCoc(double diameterPx);
/// True when every element of `m` (any depth, any channels) is finite.
bool allFinite(const cv::Mat& m);

} // namespace defocus::test
