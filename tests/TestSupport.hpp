// SPDX-License-Identifier: LGPL-2.1-or-later
// Helpers shared by the tests: where the bundled data lives, scratch folders, image statistics.
#pragma once

#include <algorithm>
#include <filesystem>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include "defocus/Frame.hpp"
#include "filter/Log.hpp"
#include "filter/Settings.hpp"

namespace defocus::test {

/// The repository's data/ folder (bundled fixtures).
std::filesystem::path dataDir();
/// The corpus' railing-lights scene (data/corpus): float colour with lights above white over
/// depth edges, behind thin foreground bars; its depth in metres.
Frame railingLights();
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
/// A quality setting the tests run, with the name they report it by.
struct NamedQuality {
    std::string name; ///< "balanced", "fast", "high", "rhombi", "mcintosh"
    QualitySettings quality;
};
/// GoogleTest prints a parameter by its name.
void PrintTo(const NamedQuality& quality, std::ostream* os);
/// The shipped presets (filter/Presets.hpp), the default (balanced) first: what users run.
std::vector<NamedQuality> shippedPresets();
/// The presets, then each kernel with the pipeline's plain settings (QualitySettings{}: 16 taps,
/// 16F, full size, no near field): "rhombi" and "mcintosh", the published chain, which no
/// preset uses.
std::vector<NamedQuality> presetsAndKernels();
/// Where the near field may spread blurred foreground (CV_8U, 255 there): every pixel within
/// |CoC| / 2 + `margin` px of a pixel whose signed CoC (`signedCoc`, CV_32F, pixels) is -0.5 or
/// less. Pixels in focus there may take a share of the foreground, by design.
cv::Mat foregroundReach(const cv::Mat& signedCoc, int margin);
/// True when every element of `m` (any depth, any channels) is finite.
bool allFinite(const cv::Mat& m);

/// Collects what the library logs (its own logger) and the program (spdlog's default) while it lives.
class LogCapture {
public:
    LogCapture() : sink_(std::make_shared<spdlog::sinks::ostream_sink_mt>(stream_))
    {
        for (spdlog::logger* logger : loggers())
            logger->sinks().push_back(sink_);
    }
    ~LogCapture()
    {
        for (spdlog::logger* logger : loggers()) {
            auto& sinks = logger->sinks();
            sinks.erase(std::remove(sinks.begin(), sinks.end(), sink_), sinks.end());
        }
    }
    LogCapture(const LogCapture&) = delete;
    LogCapture& operator=(const LogCapture&) = delete;
    std::string text() const { return stream_.str(); }

private:
    static std::vector<spdlog::logger*> loggers() { return {spdlog::default_logger_raw(), &defocus::logger()}; }
    std::ostringstream stream_;
    std::shared_ptr<spdlog::sinks::ostream_sink_mt> sink_;
};

} // namespace defocus::test
