// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-bench throughput (bench/BenchThroughput.hpp): one frame at a time against frames in flight.
#include "bench/BenchThroughput.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <optional>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "defocus/Filter.hpp"
#include "defocus/Source.hpp"
#include "samples/BenchMachine.hpp"
#include "samples/ExitStatus.hpp"

namespace defocus {
namespace {

using Clock = std::chrono::steady_clock;

double threadCpuMs()
{
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

} // namespace

int runThroughput(const ThroughputOptions& options)
{
    std::vector<Frame> clip;
    try {
        SourceSettings input;
        input.input = options.data;
        Source source(input);
        while (auto frame = source.next())
            clip.push_back(std::move(*frame));
    } catch (const Error& error) {
        fmt::print(stderr, "defocus-bench: error: {}\n", error.what());
        return kExitBadInput;
    }
    if (clip.empty()) {
        fmt::print(stderr, "defocus-bench: error: {} has no frames\n", options.data);
        return kExitBadInput;
    }
    Settings settings;
    settings.lens.focusM = 1.0;
    settings.quality.preset = qualityNamed(options.preset).value_or(Quality::Preset::Balanced);
    Filter filter(settings);
    fmt::print("{} frames of {} per pass, {} passes per way, interleaved; {} preset; on {}\n", options.frames,
               options.data, options.passes, options.preset, filter.renderer());
    fmt::print("{:>11} | {:>22} | {:>22} | {:>9} | {:>9}\n", "size", "one at a time ms (fps)",
               fmt::format("{} in flight ms (fps)", Filter::kFramesInFlight), "new/old", "CPU ms");
    int status = kExitDone;
    for (const cv::Size size : options.sizes) {
        std::vector<std::pair<cv::Mat, cv::Mat>> frames;
        for (const Frame& f : clip) {
            cv::Mat color, depth;
            cv::resize(f.color, color, size, 0, 0, cv::INTER_AREA);
            cv::resize(f.depth, depth, size, 0, 0, cv::INTER_NEAREST);
            frames.emplace_back(color, depth);
        }
        const auto at = [&](int i) -> const std::pair<cv::Mat, cv::Mat>& {
            return frames[static_cast<std::size_t>(i) % frames.size()];
        };
        std::vector<double> serialMs, flightMs, serialCpu, flightCpu;
        std::vector<cv::Mat> serialOut, flightOut; // the first pass's, compared
        filter.process(at(0).first, at(0).second); // warm: targets of this size
        for (int pass = 0; pass < options.passes; ++pass) {
            filter.reset();
            auto start = Clock::now();
            double cpu = threadCpuMs();
            for (int i = 0; i < options.frames; ++i) {
                cv::Mat out = filter.process(at(i).first, at(i).second);
                if (pass == 0)
                    serialOut.push_back(out);
            }
            serialCpu.push_back((threadCpuMs() - cpu) / options.frames);
            serialMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count() / options.frames);

            filter.reset();
            start = Clock::now();
            cpu = threadCpuMs();
            const auto take = [&] {
                cv::Mat out = *filter.receive();
                if (pass == 0)
                    flightOut.push_back(out);
            };
            for (int i = 0; i < options.frames; ++i) {
                filter.submit(at(i).first, at(i).second);
                if (filter.framesInFlight() >= Filter::kFramesInFlight)
                    take();
            }
            while (filter.framesInFlight() > 0)
                take();
            flightCpu.push_back((threadCpuMs() - cpu) / options.frames);
            flightMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count() / options.frames);
        }
        for (std::size_t i = 0; i < serialOut.size(); ++i) {
            cv::Mat diff;
            cv::absdiff(serialOut[i], flightOut[i], diff);
            if (cv::countNonZero(diff.reshape(1)) != 0) {
                fmt::print(stderr, "defocus-bench: error: {}x{} frame {}: frames in flight differ from one at a time\n",
                           size.width, size.height, i);
                status = kExitBadInput;
            }
        }
        const double serial = median(serialMs), flight = median(flightMs);
        fmt::print("{:>11} | {:>9.2f} ({:>7.1f} fps) | {:>9.2f} ({:>7.1f} fps) | {:>9.3f} | {:>4.1f} {:>4.1f}\n",
                   fmt::format("{}x{}", size.width, size.height), serial, 1e3 / serial, flight, 1e3 / flight,
                   flight / serial, median(serialCpu), median(flightCpu));
    }
    fmt::print("ms: wall per frame, median of the passes; new/old: in flight over one at a time; CPU ms: the "
               "calling thread's CPU time per frame, one at a time then in flight\n");
    return status;
}

} // namespace defocus
