// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-bench throughput (bench/BenchThroughput.hpp): one frame at a time against frames in flight.
#include "bench/BenchThroughput.hpp"

#include <algorithm>
#include <chrono>
#include <optional>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "defocus/Filter.hpp"
#include "defocus/Source.hpp"
#include "filter/gl/Objects.hpp"
#include "samples/BenchMachine.hpp"
#include "samples/ExitStatus.hpp"
#include "tests/YuvPlanes.hpp"

namespace defocus {
namespace {

using Clock = std::chrono::steady_clock;

/// --versus-yuv: the table of Y'CbCr in flight against BGR in flight, per size.
int runVersusYuv(const ThroughputOptions& options, const std::vector<Frame>& clip, Filter& filter)
{
    const YuvImage::Layout layout = options.versusYuv == "yuyv"   ? YuvImage::Layout::Yuyv
                                    : options.versusYuv == "nv12" ? YuvImage::Layout::Nv12
                                                                  : YuvImage::Layout::I420;
    const std::string name = test::layoutName(layout);
    fmt::print("{:>11} | {:>22} | {:>22} | {:>9} | {:>9}\n", "size", "BGR ms (fps)", name + " ms (fps)",
               name + "/BGR", "CPU ms");
    int status = kExitDone;
    for (const cv::Size size : options.sizes) {
        std::vector<YuvImage> yuv;
        std::vector<cv::Mat> bgr, depth;
        for (const Frame& f : clip) {
            cv::Mat color, d;
            cv::resize(f.color, color, size, 0, 0, cv::INTER_AREA);
            cv::resize(f.depth, d, size, 0, 0, cv::INTER_NEAREST);
            yuv.push_back(test::opencvYuv(color, layout)); // OpenCV's BT.601 limited range
            bgr.push_back(yuvToBgr(yuv.back())); // what the filter makes of the planes: the same frames
            depth.push_back(d);
        }
        const auto timed = [&](bool planes, std::vector<cv::Mat>* outputs, double& cpuMs) {
            filter.reset();
            const auto start = Clock::now();
            const double cpu = gl::threadCpuMs();
            const auto take = [&] {
                cv::Mat out = *filter.receive();
                if (outputs)
                    outputs->push_back(out);
            };
            for (int i = 0; i < options.frames; ++i) {
                const std::size_t k = static_cast<std::size_t>(i) % clip.size();
                if (planes)
                    filter.submit(yuv[k], depth[k]);
                else
                    filter.submit(bgr[k], depth[k]);
                if (filter.framesInFlight() >= Filter::kFramesInFlight)
                    take();
            }
            while (filter.framesInFlight() > 0)
                take();
            cpuMs = (gl::threadCpuMs() - cpu) / options.frames;
            return std::chrono::duration<double, std::milli>(Clock::now() - start).count() / options.frames;
        };
        filter.process(bgr[0], depth[0]); // warm: targets of this size
        filter.process(yuv[0], depth[0]);
        std::vector<double> bgrMs, yuvMs, bgrCpu, yuvCpu;
        std::vector<cv::Mat> bgrOut, yuvOut;
        for (int pass = 0; pass < options.passes; ++pass) {
            double cpu = 0.0;
            bgrMs.push_back(timed(false, pass == 0 ? &bgrOut : nullptr, cpu));
            bgrCpu.push_back(cpu);
            yuvMs.push_back(timed(true, pass == 0 ? &yuvOut : nullptr, cpu));
            yuvCpu.push_back(cpu);
        }
        for (std::size_t i = 0; i < bgrOut.size(); ++i) {
            cv::Mat diff;
            cv::absdiff(bgrOut[i], yuvOut[i], diff);
            if (cv::countNonZero(diff.reshape(1)) != 0) {
                fmt::print(stderr, "defocus-bench: error: {}x{} frame {}: {} differs from its BGR\n", size.width,
                           size.height, i, name);
                status = kExitBadInput;
            }
        }
        const double b = median(bgrMs), y = median(yuvMs);
        fmt::print("{:>11} | {:>9.2f} ({:>7.1f} fps) | {:>9.2f} ({:>7.1f} fps) | {:>9.3f} | {:>4.1f} {:>4.1f}\n",
                   fmt::format("{}x{}", size.width, size.height), b, 1e3 / b, y, 1e3 / y, y / b, median(bgrCpu),
                   median(yuvCpu));
    }
    fmt::print("ms: wall per frame with {} in flight, median of the passes; CPU ms: the calling thread's CPU time "
               "per frame, BGR then {}\n",
               Filter::kFramesInFlight, name);
    return status;
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
    if (!options.versusYuv.empty())
        return runVersusYuv(options, clip, filter);
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
            double cpu = gl::threadCpuMs();
            for (int i = 0; i < options.frames; ++i) {
                cv::Mat out = filter.process(at(i).first, at(i).second);
                if (pass == 0)
                    serialOut.push_back(out);
            }
            serialCpu.push_back((gl::threadCpuMs() - cpu) / options.frames);
            serialMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count() / options.frames);

            filter.reset();
            start = Clock::now();
            cpu = gl::threadCpuMs();
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
            flightCpu.push_back((gl::threadCpuMs() - cpu) / options.frames);
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
