// SPDX-License-Identifier: LGPL-2.1-or-later
// Soak: many frames through the pipeline, checking that memory and GL objects stay flat.
//   defocus-soak --frames 10000 --width 160 --height 120 [--quality balanced]
// Frames alternate between two sizes every 50 frames, so target reallocation is exercised too.
// Exits 1 when resident memory grows by more than --max-growth-mb or GL objects leak, 2 on a bad
// command line, 75 without a GL context (samples/ExitStatus.hpp).
#include <cstdio>
#include <fstream>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <unistd.h>

#include "bench/BenchCli.hpp"
#include "filter/Pipeline.hpp"
#include "filter/Presets.hpp"
#include "filter/gl/EglContext.hpp"
#include "filter/gl/Objects.hpp"
#include "samples/CliOptions.hpp"
#include "samples/ExitStatus.hpp"

namespace {

using namespace defocus;

/// Resident set size in MiB, from /proc/self/statm.
double residentMiB()
{
    std::ifstream statm("/proc/self/statm");
    long pages = 0, resident = 0;
    statm >> pages >> resident;
    return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

Frame syntheticFrame(int width, int height, std::size_t index)
{
    Frame frame;
    frame.color.create(height, width, CV_8UC3);
    cv::randu(frame.color, 0, 256);
    frame.depth.create(height, width, CV_32F);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            frame.depth.at<float>(y, x) = (x + y) % 17 == 0 ? 0.0f : 0.5f + 4.0f * static_cast<float>(x) / static_cast<float>(width);
    frame.index = index;
    frame.name = fmt::format("synthetic {}", index);
    return frame;
}

} // namespace

int main(int argc, char** argv)
{
    std::size_t frames = 10000;
    int width = 160, height = 120;
    double maxGrowthMiB = 4.0;
    std::string qualityName(kDefaultPreset);
    CLI::App app{"defocus-soak: frames through the pipeline with flat memory and GL object counts"};
    app.add_option("--frames", frames, "Frames to run")->capture_default_str();
    app.add_option("--width", width, "Frame width, pixels")->capture_default_str()->check(cli::between(2, 8192));
    app.add_option("--height", height, "Frame height, pixels")->capture_default_str()->check(cli::between(2, 8192));
    app.add_option("--max-growth-mb", maxGrowthMiB, "Allowed RSS growth after warm-up, MiB")->capture_default_str();
    app.add_option("--quality", qualityName, "Preset the frames run with, as defocus --quality")
        ->capture_default_str()
        ->check(CLI::IsMember({"fast", "balanced", "high"}));
    if (const auto status = cli::parse(app, argc, argv))
        return *status;
    cli::logToStderr("defocus-soak");

    try {
        auto context = gl::EglContext::create();
        const QualitySettings quality = presetSettings(qualityName);
        Pipeline pipeline;
        LensSettings lens;
        lens.focusM = 2.0;
        lens.fNumber = 1.4;
        // Two sizes, a pool of prepared frames each: the soak measures the pipeline, not rand().
        const cv::Size sizes[2] = {{width, height}, {width / 2 + 1, height / 2 + 1}};
        std::vector<Frame> pool[2];
        for (int s = 0; s < 2; ++s)
            for (std::size_t i = 0; i < 4; ++i)
                pool[s].push_back(syntheticFrame(sizes[s].width, sizes[s].height, i));

        const std::size_t warmup = std::min<std::size_t>(200, frames / 2);
        double rssStart = 0.0;
        long objectsStart = 0;
        for (std::size_t i = 0; i < frames; ++i) {
            const int s = static_cast<int>((i / 50) % 2);
            const cv::Mat out = pipeline.run(pool[s][i % 4], lens, quality);
            if (out.size() != sizes[s]) {
                std::fprintf(stderr, "defocus-soak: frame %zu came out %dx%d\n", i, out.cols, out.rows);
                return 1;
            }
            if (i + 1 == warmup) {
                rssStart = residentMiB();
                objectsStart = gl::liveObjects.load();
            }
        }
        // Back on the size the warm-up ended on, so the same targets exist.
        const int lastSize = static_cast<int>(((warmup - 1) / 50) % 2);
        pipeline.run(pool[lastSize][0], lens, quality);
        const double rssEnd = residentMiB();
        const long objectsEnd = gl::liveObjects.load();
        std::printf("defocus-soak: %zu frames (%dx%d and %dx%d, --quality %s), RSS %.1f -> %.1f MiB after %zu warm-up "
                    "frames, GL objects %ld -> %ld\n",
                    frames, sizes[0].width, sizes[0].height, sizes[1].width, sizes[1].height, qualityName.c_str(), rssStart, rssEnd, warmup,
                    objectsStart, objectsEnd);
        if (rssEnd - rssStart > maxGrowthMiB || objectsEnd != objectsStart) {
            std::fprintf(stderr, "defocus-soak: memory or GL objects grew\n");
            return 1;
        }
        return 0;
    } catch (const std::exception& error) {
        std::fprintf(stderr, "defocus-soak: error: %s\n", error.what());
        return bench::statusFor(error);
    }
}
