// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-bench: speed of the McIntosh pipeline, ms per pass and per frame, on the bundled TUM clip
// resized to each frame size, for a defocused and an all-in-focus scene. A benchmark, not a test.
//   defocus-bench                                    (run from the repository root)
//   defocus-bench --sizes 640x480 --runs 30 --json out/bench.json
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "bench/BenchCli.hpp"
#include "bench/BenchPlan.hpp"
#include "bench/BenchThroughput.hpp"
#include "bench/BenchTiming.hpp"
#include "filter/ApiSettings.hpp"
#include "filter/DepthPrep.hpp"
#include "filter/Lens.hpp"
#include "filter/Pipeline.hpp"
#include "filter/Presets.hpp"
#include "filter/Settings.hpp"
#include "filter/gl/EglContext.hpp"
#include "filter/gl/Objects.hpp"
#include "filter/gl/Renderer.hpp"
#include "samples/BenchMachine.hpp"
#include "samples/CliOptions.hpp"
#include "samples/ExitStatus.hpp"
#include "sinks/BackgroundSink.hpp"
#include "sinks/FrameSink.hpp"
#include "sources/FrameSource.hpp"
#include "sources/ReadAheadSource.hpp"

#include <unistd.h>

namespace {

using namespace defocus;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

/// Exit codes: 0 done, 1 runtime failure (data, GL, output), 2 bad command line.

/// The command line; --quality and the options that override it are defocus's
/// (cli::addQualityOptions), resolved by cli::finishQuality into `quality`.
struct Options : cli::QualityNames {
    Quality quality;
    std::string data = "data/tum_fr1_rpy";
    std::vector<std::string> sizes = {"640x480", "1920x1080"};
    int runs = 15;
    int warmup = 3;
    double focusM = 1.0;
    double fNumber = 2.0;
    double focalLengthMm = 50.0;
    double maxCocAt640 = 32.0;
    int blades = 6; ///< LensSettings::blades, bladeRotationDeg, apertureRatio
    double bladeRotationDeg = 0.0;
    double apertureRatio = 1.0;
    bool noTimers = false;
    bool noAdaptive = false;
    bool finishEachPass = false;
    bool quarterOnLargeBlur = false; ///< QualitySettings::quarterOnLargeBlur on (the presets leave it off)
    /// Also time the defocused scene always at half size (QualitySettings::quarterOnLargeBlur
    /// off: the path before quarter size), in a second pipeline, frame by frame alternating with
    /// the first: before and after as a ratio within one run.
    bool versusHalfOnly = false;
    /// Depth prep and the scene measurement on the GPU in the main pipeline, and also the
    /// defocused scene with them on the CPU (Pipeline::prepareOnGpu off), in a second pipeline,
    /// frames alternating as above.
    bool versusCpuPrep = false;
    /// The passes as compute shaders in the main pipeline, and also the defocused scene with
    /// them drawn by their fragment shaders (Pipeline::computePasses off), in a second pipeline,
    /// frames alternating as above.
    bool versusFragment = false;
    std::string json;
};

/// One measured quantity over the runs of one scene, in milliseconds.
struct Series {
    std::string key;   ///< JSON name
    std::string label; ///< table row
    std::vector<double> ms;
};

/// All series of one (size, scene), in table order: GPU passes as the pipeline reports them,
/// their sum, then the CPU-side wall times.
struct SceneResult {
    std::string scene;
    std::vector<Series> gpu;
    std::vector<Series> wall;
    double othersCpuShare = -1.0; ///< CPU share other processes used during the runs; -1 unknown
    int quarterFrames = 0;        ///< measured frames whose plan blurred at quarter size
    int measuredFrames = 0;
};

/// How the lens spreads blur over the defocused scene, so the figures can be read against it.
struct CocSpread {
    double sharpShare = 0.0;   ///< |CoC| < 0.5 px
    double nearShare = 0.0;    ///< CoC <= -0.5 px (in front of the focus)
    double farShare = 0.0;     ///< CoC >= 0.5 px (behind it)
    double clampedShare = 0.0; ///< |CoC| at max-coc
    double medianAbsPx = 0.0;
    double p90AbsPx = 0.0;
};

cv::Size parseSize(const std::string& text)
{
    int width = 0, height = 0;
    char separator = 0;
    char rest = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &width, &separator, &height, &rest) != 3 ||
        (separator != 'x' && separator != 'X') || width < 16 || height < 16 || width > 8192 || height > 8192)
        throw CLI::ValidationError("--sizes", fmt::format("'{}' is not WIDTHxHEIGHT with sides in [16, 8192]", text));
    return {width, height};
}

/// The 1-minute load average, to tell a quiet machine from a busy one; -1 when unknown.
double loadAverage()
{
    std::ifstream file("/proc/loadavg");
    double load = -1.0;
    file >> load;
    return file ? load : -1.0;
}

/// CPU seconds spent so far: by the whole machine (all cores, from /proc/stat) and by this
/// process (getrusage). The difference over a measurement is what other processes took.
struct CpuClock {
    double machineBusyS = -1.0;
    double machineTotalS = -1.0;
    double selfS = 0.0;

    static CpuClock now()
    {
        CpuClock clock;
        rusage usage{};
        getrusage(RUSAGE_SELF, &usage);
        const auto seconds = [](const timeval& t) {
            return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
        };
        clock.selfS = seconds(usage.ru_utime) + seconds(usage.ru_stime);
        std::ifstream stat("/proc/stat");
        std::string cpu;
        double user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0, steal = 0;
        if (stat >> cpu >> user >> nice >> system >> idle >> iowait >> irq >> softirq >> steal && cpu == "cpu") {
            const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
            clock.machineBusyS = (user + nice + system + irq + softirq + steal) / tick;
            clock.machineTotalS = clock.machineBusyS + (idle + iowait) / tick;
        }
        return clock;
    }

    /// Share of all CPU time between `start` and this clock that went to other processes.
    double othersShareSince(const CpuClock& start) const
    {
        const double total = machineTotalS - start.machineTotalS;
        if (start.machineTotalS < 0 || machineTotalS < 0 || total <= 0)
            return -1.0;
        const double others = (machineBusyS - start.machineBusyS) - (selfS - start.selfS);
        return std::clamp(others / total, 0.0, 1.0);
    }
};

/// Reads every frame of the clip once; the runs then cycle through them.
std::vector<Frame> loadClip(const fs::path& folder)
{
    std::error_code ec;
    if (!fs::is_directory(folder, ec))
        throw std::runtime_error(fmt::format(
            "data folder '{}' not found (looked from '{}'); run from the repository root or pass --data DIR",
            folder.string(), fs::current_path(ec).string()));
    auto source = openSource(SourceOptions{folder, std::nullopt, std::nullopt});
    std::vector<Frame> frames;
    while (auto frame = source->next()) {
        if (frame->depth.empty())
            throw std::runtime_error(fmt::format("{}: frame {} has no depth", folder.string(), frame->name));
        frames.push_back(std::move(*frame));
    }
    if (frames.empty())
        throw std::runtime_error(fmt::format("{} gave no frames", source->describe()));
    return frames;
}

/// The clip at `size`: colour by area averaging (shrinking) or bilinear (enlarging), depth by
/// nearest neighbour so no depth is invented across edges and holes stay holes.
std::vector<Frame> resizeClip(const std::vector<Frame>& clip, cv::Size size)
{
    std::vector<Frame> frames;
    for (const Frame& original : clip) {
        Frame frame = original;
        if (original.color.size() != size) {
            const bool shrinking = size.area() < original.color.size().area();
            cv::resize(original.color, frame.color, size, 0, 0, shrinking ? cv::INTER_AREA : cv::INTER_LINEAR);
        }
        if (original.depth.size() != size)
            cv::resize(original.depth, frame.depth, size, 0, 0, cv::INTER_NEAREST);
        frames.push_back(std::move(frame));
    }
    return frames;
}

/// The same colour, every depth on the focus plane: the cost of a frame with nothing to blur.
std::vector<Frame> inFocusClip(const std::vector<Frame>& clip, float focusM)
{
    std::vector<Frame> frames = clip;
    for (Frame& frame : frames)
        frame.depth = cv::Mat(frame.color.size(), CV_32FC1, cv::Scalar(focusM));
    return frames;
}

CocSpread cocSpread(const std::vector<Frame>& frames, const LensSettings& lens)
{
    std::vector<double> absCoc;
    std::size_t near = 0, far = 0, clamped = 0;
    for (const Frame& frame : frames) {
        const CocCoefficients k = cocCoefficients(lens, frame.color.cols);
        const PreparedDepth depth = prepareDepth(frame.depth, frame.color.size(), static_cast<float>(lens.focusM));
        for (int y = 0; y < depth.metres.rows; ++y) {
            const float* row = depth.metres.ptr<float>(y);
            for (int x = 0; x < depth.metres.cols; ++x) {
                const float c = cocPixels(k, row[x]);
                near += c <= -0.5f;
                far += c >= 0.5f;
                clamped += std::abs(c) >= k.maxCocPx;
                absCoc.push_back(std::abs(c));
            }
        }
    }
    const auto share = [&](std::size_t count) {
        return static_cast<double>(count) / static_cast<double>(absCoc.size());
    };
    CocSpread spread;
    spread.nearShare = share(near);
    spread.farShare = share(far);
    spread.sharpShare = 1.0 - spread.nearShare - spread.farShare;
    spread.clampedShare = share(clamped);
    const auto middle = absCoc.begin() + static_cast<std::ptrdiff_t>(absCoc.size() / 2);
    std::nth_element(absCoc.begin(), middle, absCoc.end());
    spread.medianAbsPx = *middle;
    const auto top = absCoc.begin() + static_cast<std::ptrdiff_t>(absCoc.size() * 9 / 10);
    std::nth_element(absCoc.begin(), top, absCoc.end());
    spread.p90AbsPx = *top;
    return spread;
}

Series& seriesNamed(std::vector<Series>& all, const std::string& key, const std::string& label)
{
    for (Series& series : all)
        if (series.key == key)
            return series;
    all.push_back({key, label, {}});
    return all.back();
}

/// One pipeline and its settings, measured side by side with others.
struct Variant {
    std::string scene; ///< the table's column
    Pipeline* pipeline;
    QualitySettings quality;
};

/// Runs `frames` (cycled) through each variant's pipeline, frame by frame alternating between
/// them so that a slower or busier stretch of the machine falls on all of them alike:
/// `options.warmup` frames unmeasured, then `options.runs` measured ones. GPU timer results
/// arrive one frame late, tagged with the index of the frame they belong to, so every frame gets
/// a unique index and one extra frame at the end delivers the GPU times of the last measured one.
std::vector<SceneResult> measure(const std::vector<Variant>& variants, std::size_t& counter,
                                 const std::vector<Frame>& frames, const LensSettings& lens, const Options& options)
{
    const auto runFrame = [&](const Variant& variant, int i) {
        Frame frame = frames[static_cast<std::size_t>(i) % frames.size()];
        frame.index = counter++;
        variant.pipeline->run(frame, lens, variant.quality);
        return frame.index;
    };
    for (int i = 0; i < options.warmup; ++i)
        for (const Variant& variant : variants)
            runFrame(variant, i);

    struct Collected {
        SceneResult result;
        std::vector<double> gpuSum, depthPrep, analysis, upload, render, readback, total, thread, waiting;
        double cpuSeconds = 0.0, othersSeconds = 0.0;
    };
    std::vector<Collected> collected(variants.size());
    const std::size_t firstMeasured = counter;
    const auto takeGpu = [&](Collected& c, const FrameTimings& t) {
        if (t.gpu.empty() || t.gpuFrame < firstMeasured)
            return;
        double sum = 0.0;
        for (const PassTime& pass : t.gpu) {
            seriesNamed(c.result.gpu, pass.name, "GPU " + pass.name).ms.push_back(pass.ms);
            sum += pass.ms;
        }
        c.gpuSum.push_back(sum);
    };
    const CpuClock cpuStart = CpuClock::now();
    for (int i = 0; i < options.runs; ++i)
        for (std::size_t v = 0; v < variants.size(); ++v) {
            // The calling thread's CPU time: what a frame costs it besides waiting (the driver's
            // own threads, llvmpipe's rasteriser among them, are not counted), and of it what the
            // fence waits took (a driver that spins while it waits charges them here).
            const double threadStart = gl::threadCpuMs();
            const double waitStart = gl::fenceWaits().cpuMs;
            runFrame(variants[v], options.warmup + i);
            collected[v].thread.push_back(gl::threadCpuMs() - threadStart);
            collected[v].waiting.push_back(gl::fenceWaits().cpuMs - waitStart);
            const FrameTimings& t = variants[v].pipeline->timings();
            Collected& c = collected[v];
            c.result.quarterFrames += variants[v].pipeline->plan().blurShift == 2 ? 1 : 0;
            ++c.result.measuredFrames;
            takeGpu(c, t);
            c.depthPrep.push_back(t.depthPrepMs);
            c.analysis.push_back(t.analysisMs);
            c.upload.push_back(t.uploadMs);
            c.render.push_back(t.renderMs);
            c.readback.push_back(t.readbackMs);
            c.total.push_back(t.totalMs);
        }
    const double othersShare = CpuClock::now().othersShareSince(cpuStart);
    for (std::size_t v = 0; v < variants.size(); ++v) {
        runFrame(variants[v], options.warmup + options.runs);
        takeGpu(collected[v], variants[v].pipeline->timings());
    }

    std::vector<SceneResult> results;
    for (std::size_t v = 0; v < variants.size(); ++v) {
        Collected& c = collected[v];
        SceneResult result = std::move(c.result);
        result.scene = variants[v].scene;
        result.othersCpuShare = othersShare;
        if (!c.gpuSum.empty())
            result.gpu.push_back({"sum", "GPU sum of passes", c.gpuSum});
        result.wall = {{"callingThreadCpu", "calling thread's CPU", c.thread},
                       {"callingThreadWaitCpu", "of which in fence waits", c.waiting},
                       {"depthPrep", "depth prep (submit or CPU)", c.depthPrep},
                       {"analysis", "analysis + plan (wall)", c.analysis},
                       {"upload", "upload (wall)", c.upload},
                       {"renderSubmit", "render submit (wall)", c.render},
                       {"readback", "readback (wall)", c.readback},
                       {"total", "total per frame (wall)", c.total}};
        results.push_back(std::move(result));
    }
    return results;
}

/// Rows of both scenes side by side: label, then median and p90 of each scene.
void printTable(const std::vector<SceneResult>& scenes)
{
    std::string header = fmt::format("{:<26}", "ms");
    std::string subheader = fmt::format("{:<26}", "");
    for (const SceneResult& scene : scenes) {
        header += fmt::format("{:>20}", scene.scene);
        subheader += fmt::format("{:>10}{:>10}", "median", "p90");
    }
    fmt::print("{}\n{}\n", header, subheader);

    const auto row = [&](const std::string& label, const auto& pick) {
        std::string line = fmt::format("{:<26}", label);
        for (const SceneResult& scene : scenes) {
            const Series* series = pick(scene);
            if (series && !series->ms.empty())
                line += fmt::format("{:>10.2f}{:>10.2f}", median(series->ms), p90(series->ms));
            else
                line += fmt::format("{:>10}{:>10}", "n/a", "n/a");
        }
        fmt::print("{}\n", line);
    };
    std::vector<std::pair<std::string, std::string>> gpuRows; // key, label, in first-seen order
    for (const SceneResult& scene : scenes)
        for (const Series& series : scene.gpu)
            if (std::none_of(gpuRows.begin(), gpuRows.end(), [&](const auto& r) { return r.first == series.key; }))
                gpuRows.emplace_back(series.key, series.label);
    for (const auto& [key, label] : gpuRows)
        row(label, [&key](const SceneResult& scene) -> const Series* {
            for (const Series& series : scene.gpu)
                if (series.key == key)
                    return &series;
            return nullptr;
        });
    for (std::size_t i = 0; i < scenes.front().wall.size(); ++i)
        row(scenes.front().wall[i].label,
            [i](const SceneResult& scene) -> const Series* { return &scene.wall[i]; });

    std::string fps = fmt::format("{:<26}", "frames per second");
    for (const SceneResult& scene : scenes)
        fps += fmt::format("{:>10.1f}{:>10}", 1000.0 / median(scene.wall.back().ms), "");
    fmt::print("{}\n", fps);
}

Json seriesJson(const std::vector<Series>& all)
{
    Json object = Json::object();
    for (const Series& series : all)
        object[series.key] = {{"median", median(series.ms)}, {"p90", p90(series.ms)}, {"runs", series.ms}};
    return object;
}

int run(const Options& options, const std::string& commandLine)
{
    std::vector<cv::Size> sizes;
    for (const std::string& text : options.sizes)
        sizes.push_back(parseSize(text));

    QualitySettings quality = toQuality(options.quality); // the preset under the options given
    quality.adaptive = !options.noAdaptive;
    if (options.quarterOnLargeBlur)
        quality.quarterOnLargeBlur = true;
    const std::string precision = quality.targetFormat == TargetFormat::Rgba32F   ? "32f"
                                  : quality.targetFormat == TargetFormat::Rgba16F ? "16f"
                                                                                  : "auto";
    LensSettings baseLens;
    baseLens.model = CocModel::ThinLens;
    baseLens.focusM = options.focusM;
    baseLens.fNumber = options.fNumber;
    baseLens.focalLengthMm = options.focalLengthMm;
    baseLens.blades = options.blades;
    baseLens.bladeRotationDeg = options.bladeRotationDeg;
    baseLens.apertureRatio = options.apertureRatio;
    {
        auto issues = validate(quality);
        for (const cv::Size size : sizes) {
            LensSettings lens = baseLens;
            lens.maxCocPx = options.maxCocAt640 * size.width / 640.0;
            const auto lensIssues = validate(lens);
            issues.insert(issues.end(), lensIssues.begin(), lensIssues.end());
        }
        for (const auto& issue : issues)
            fmt::print(stderr, "defocus-bench: error: {}\n", issue.message);
        if (!issues.empty())
            return kExitUsage;
    }

    const std::vector<Frame> clip = loadClip(options.data);
    auto context = gl::EglContext::create();
    const gl::ContextInfo& info = context.info();
    Pipeline pipeline(!options.noTimers);
    pipeline.finishEachPass(options.finishEachPass);
    std::optional<Pipeline> versusPipeline;
    QualitySettings versusQuality = quality;
    std::string versusScene;
    // The second pipeline, named `scene`, timed like the first.
    const auto versus = [&](std::string scene) -> Pipeline& {
        versusPipeline.emplace(!options.noTimers);
        versusPipeline->finishEachPass(options.finishEachPass);
        versusScene = std::move(scene);
        return *versusPipeline;
    };
    // The main pipeline takes the way measured whatever the renderer's default; the second the other.
    if (options.versusHalfOnly) {
        versusQuality.quarterOnLargeBlur = false;
        versus("half only");
    } else if (options.versusCpuPrep) {
        pipeline.prepareOnGpu(true);
        versus("CPU depth prep").prepareOnGpu(false);
    } else if (options.versusFragment) {
        pipeline.computePasses(true);
        versus("fragment passes").computePasses(false);
    }

    const unsigned cores = std::thread::hardware_concurrency();
    const std::string cpu = cpuModel();
    const double loadBefore = loadAverage();
    fmt::print("defocus-bench, {}\n", utcNow());
    fmt::print("GL renderer: {}; GL {}; EGL platform: {}\nCPU: {}, {} cores; load average {:.2f} before the runs "
               "(figures are only comparable on an otherwise idle machine)\n",
               info.glRenderer, info.glVersion, info.platform, cpu, cores, loadBefore);
    fmt::print("clip: {} ({} frames, cycled); --quality {}: {} {} taps{}, {} size, {}, {}; {} runs after {} warm-up "
               "frames per scene\n",
               options.data, clip.size(), options.qualityPreset, kernelName(quality.kernel), quality.samples,
               quality.nearField ? " + near field" : "",
               quality.resolution == Resolution::Half && quality.quarterOnLargeBlur ? "half (quarter on large blur)"
                                                                                    : resolutionName(quality.resolution),
               precision == "32f"   ? "RGBA32F"
               : precision == "16f" ? "RGBA16F"
                                    : (gl::halfFloatTargets(info.glRenderer) ? "RGBA16F (the renderer's)"
                                                                           : "RGBA32F (the renderer's)"),
               quality.adaptive ? "adaptive (in-focus frames and tiles skipped)" : "every pass on every pixel",
               options.runs, options.warmup);
    fmt::print("passes: {} shaders{}\n",
               options.versusFragment || gl::computePasses(info.glRenderer) ? "compute" : "fragment",
               options.versusFragment ? "" : " (the renderer's; DEFOCUS_PASSES=compute or fragment chooses)");
    fmt::print("lens: thin lens {} mm f/{} focused at {} m, 36 mm sensor, max-coc {} px per 640 px of width; "
               "aperture: {}, rotated {} deg, ratio {}\n",
               options.focalLengthMm, options.fNumber, options.focusM, options.maxCocAt640,
               options.blades == 0 ? std::string("circle") : fmt::format("{} blades", options.blades),
               options.bladeRotationDeg, options.apertureRatio);
    if (options.versusHalfOnly)
        fmt::print("versus: the defocused scene also always at half size (no quarter size on large blur: the path "
                   "before it), in a second pipeline, frames alternating between the two\n");
    if (options.versusCpuPrep)
        fmt::print("versus: the defocused scene also with depth prep and the scene measurement on the CPU, the "
                   "filled depth uploaded, in a second pipeline, frames alternating between the two\n");
    if (options.versusFragment)
        fmt::print("versus: the passes as compute shaders, and the defocused scene also with them drawn by their "
                   "fragment shaders, in a second pipeline, frames alternating between the two\n");
    fmt::print("GPU = {}{}; wall = CPU clock; readback waits for the GPU to finish.\n"
               "Sizes other than the clip's are resized from it (aspect not kept); a row of n/a: the pass did "
               "not run.\nother processes' CPU %: share of all cores other programs used during the runs; "
               "above a few %, the figures are inflated.\n",
               options.finishEachPass ? "wall ms per pass, glFinish before and after each (--finish-each-pass)"
                                      : "GL_TIME_ELAPSED per pass",
               options.finishEachPass ? ""
               : options.noTimers     ? " (off: --no-timers)"
               : info.timerQueries    ? ""
                                      : " (not offered by this driver: n/a)");
    fmt::print("command: {}\n", commandLine);

    Json results = Json::array();
    std::size_t counter = 0; // unique frame index, to match GPU times to their frame
    for (const cv::Size size : sizes) {
        LensSettings lens = baseLens;
        lens.maxCocPx = options.maxCocAt640 * size.width / 640.0;
        const std::vector<Frame> frames = resizeClip(clip, size);
        const CocSpread spread = cocSpread(frames, lens);

        fmt::print(stderr, "defocus-bench: measuring {}x{}\n", size.width, size.height);
        std::vector<Variant> defocused{{"defocused", &pipeline, quality}};
        if (versusPipeline)
            defocused.push_back({versusScene, &*versusPipeline, versusQuality});
        std::vector<SceneResult> scenes = measure(defocused, counter, frames, lens, options);
        scenes.push_back(measure({{"all in focus", &pipeline, quality}}, counter,
                                 inFocusClip(frames, static_cast<float>(lens.focusM)), lens, options)
                             .front());

        fmt::print("\n{}x{}, max-coc {:.0f} px. CoC of the defocused scene: {:.0f}% sharp (<0.5 px), {:.0f}% near, "
                   "{:.0f}% far, {:.0f}% clamped; |CoC| median {:.1f} px, p90 {:.1f} px\n",
                   size.width, size.height, lens.maxCocPx, 100 * spread.sharpShare, 100 * spread.nearShare,
                   100 * spread.farShare, 100 * spread.clampedShare, spread.medianAbsPx, spread.p90AbsPx);
        printTable(scenes);
        std::string others = fmt::format("{:<26}", "other processes' CPU %");
        for (const SceneResult& scene : scenes)
            others += scene.othersCpuShare < 0 ? fmt::format("{:>10}{:>10}", "n/a", "")
                                               : fmt::format("{:>10.0f}{:>10}", 100 * scene.othersCpuShare, "");
        fmt::print("{}\n", others);
        std::string quarter = fmt::format("{:<26}", "frames at quarter size");
        for (const SceneResult& scene : scenes)
            quarter += fmt::format("{:>10}{:>10}", fmt::format("{}/{}", scene.quarterFrames, scene.measuredFrames), "");
        fmt::print("{}\n", quarter);
        if (versusPipeline)
            fmt::print("{:<26}{:>10.3f}   (defocused / {}, medians of total per frame)\n", "ratio of frame times",
                       median(scenes[0].wall.back().ms) / median(scenes[1].wall.back().ms), versusScene);

        for (const SceneResult& scene : scenes) {
            Json entry = {{"size", fmt::format("{}x{}", size.width, size.height)},
                          {"width", size.width},
                          {"height", size.height},
                          {"scene", scene.scene},
                          {"maxCocPx", lens.maxCocPx}};
            if (scene.scene == "defocused")
                entry["cocSpread"] = {{"sharpShare", spread.sharpShare},   {"nearShare", spread.nearShare},
                                      {"farShare", spread.farShare},       {"clampedShare", spread.clampedShare},
                                      {"medianAbsPx", spread.medianAbsPx}, {"p90AbsPx", spread.p90AbsPx}};
            entry["othersCpuShare"] = scene.othersCpuShare;
            entry["quarterSizeFrames"] = scene.quarterFrames;
            entry["gpuMs"] = seriesJson(scene.gpu);
            entry["wallMs"] = seriesJson(scene.wall);
            results.push_back(std::move(entry));
        }
    }

    if (!options.json.empty()) {
        const Json document = {
            {"tool", "defocus-bench"},
            {"date", utcNow()},
            {"command", commandLine},
            {"gl",
             {{"renderer", info.glRenderer},
              {"version", info.glVersion},
              {"vendor", info.glVendor},
              {"eglPlatform", info.platform},
              {"timerQueries", info.timerQueries && !options.noTimers}}},
            {"cpu", {{"model", cpu}, {"cores", cores}, {"loadAverageBefore", loadBefore}}},
            {"settings",
             {{"data", options.data},
              {"runs", options.runs},
              {"warmup", options.warmup},
              {"preset", options.qualityPreset},
              {"kernel", kernelName(quality.kernel)},
              {"nearField", quality.nearField},
              {"samples", quality.samples},
              {"resolution", resolutionName(quality.resolution)},
              {"precision", precision},
              {"adaptive", quality.adaptive},
              {"finishEachPass", options.finishEachPass},
              {"versusHalfOnly", options.versusHalfOnly},
              {"versusCpuPrep", options.versusCpuPrep},
              {"versusFragment", options.versusFragment},
              {"quarterOnLargeBlur", quality.quarterOnLargeBlur},
              {"focusM", options.focusM},
              {"fNumber", options.fNumber},
              {"focalLengthMm", options.focalLengthMm},
              {"sensorWidthMm", baseLens.sensorWidthMm},
              {"maxCocPxPer640", options.maxCocAt640},
              {"blades", options.blades},
              {"bladeRotationDeg", options.bladeRotationDeg},
              {"apertureRatio", options.apertureRatio}}},
            {"results", results}};
        std::ofstream file(options.json);
        file << document.dump(2) << '\n';
        if (!file)
            throw std::runtime_error(fmt::format("cannot write '{}'", options.json));
        fmt::print("\nwrote {}\n", options.json);
    }
    return kExitDone;
}

} // namespace

namespace {

/// `defocus-bench timing`: the per-preset timing baseline and comparator (bench/BenchTiming.hpp).
CLI::App* declareTiming(CLI::App& app, defocus::TimingOptions& o)
{
    CLI::App* sub = app.add_subcommand("timing", "For each preset, the frame's wall time (with readback) and each "
                                                 "pass's GPU time over a calibration pass measured in the same run, "
                                                 "written as a baseline or compared with one");
    sub->add_option("--data", o.data, "TUM RGB-D folder to take frames from")->capture_default_str();
    sub->add_option("--baseline", o.baseline,
                    "Compare with this baseline JSON; exit 1 on a regression, a missing or renamed preset or pass, "
                    "or a frame all in focus");
    sub->add_option("--write-baseline", o.writeBaseline, "Write the measured ratios to this JSON file");
    sub->add_option("--quality", o.presets, "Presets timed, comma-separated: fast, balanced, high [default: all]")
        ->delimiter(',')
        ->check(CLI::IsMember({"fast", "balanced", "high"}));
    sub->add_option("--runs", o.runs, "Measured frames per preset")->capture_default_str()->check(cli::between(3, 10000));
    sub->add_option("--max-ratio", o.maxRatio, "Largest allowed growth of a preset's frame ratio over the baseline's")
        ->capture_default_str()
        ->check(cli::positive());
    sub->add_option("--f-number", o.fNumber, "Lens of the timed frames (50 mm focused at 1 m): f-number")
        ->capture_default_str()
        ->check(cli::between(0.7, 64.0));
    sub->add_option("--max-coc", o.maxCocPx, "Largest blur diameter, pixels")
        ->capture_default_str()
        ->check(cli::between(0.0, 512.0));
    return sub;
}

/// `defocus-bench plan`: the plan against every pass on every pixel (bench/BenchPlan.hpp).
CLI::App* declarePlan(CLI::App& app, defocus::PlanOptions& o)
{
    CLI::App* sub = app.add_subcommand("plan", "ms per frame with the per-frame plan and with every pass on every "
                                               "pixel, and how far apart their outputs are, on the TUM clip (f/2, "
                                               "f/22) and the synthetic clips");
    sub->add_option("--data", o.data, "TUM RGB-D folder")->capture_default_str();
    sub->add_option("--quality", o.preset, "Preset: fast, balanced or high")
        ->check(CLI::IsMember({"fast", "balanced", "high"}))
        ->capture_default_str();
    sub->add_option("--passes", o.passes, "Timed passes over each clip per mode")
        ->capture_default_str()
        ->check(cli::between(1, 1000));
    sub->add_option("--synthetic-frames", o.syntheticFrames, "Frames of each synthetic clip")
        ->capture_default_str()
        ->check(cli::between(1, 10000));
    return sub;
}

/// `defocus-bench throughput`: one frame at a time against frames in flight (bench/BenchThroughput.hpp).
CLI::App* declareThroughput(CLI::App& app, defocus::ThroughputOptions& o)
{
    CLI::App* sub = app.add_subcommand("throughput", "Frames per second through the public Filter one frame at a "
                                                     "time and with frames in flight, interleaved in one run, and "
                                                     "the calling thread's CPU time per frame");
    sub->add_option("--data", o.data, "TUM RGB-D folder to take frames from")->capture_default_str();
    sub->add_option_function<std::vector<std::string>>(
           "--sizes",
           [&o](const std::vector<std::string>& texts) {
               o.sizes.clear();
               for (const std::string& text : texts)
                   o.sizes.push_back(parseSize(text));
           },
           "Frame sizes, WxH comma-separated")
        ->delimiter(',')
        ->default_str("640x480,1920x1080");
    sub->add_option("--quality", o.preset, "Preset: fast, balanced or high")
        ->check(CLI::IsMember({"fast", "balanced", "high"}))
        ->capture_default_str();
    sub->add_option("--frames", o.frames, "Frames per timed pass")->capture_default_str()->check(cli::between(2, 100000));
    sub->add_option("--passes", o.passes, "Timed passes per way, interleaved")
        ->capture_default_str()
        ->check(cli::between(1, 1000));
    sub->add_option("--versus-yuv", o.versusYuv,
                    "Instead: frames in flight with the colour as Y'CbCr planes (i420, nv12 or a webcam's yuyv) "
                    "against the same frames as BGR, interleaved, and a check that both give the same bytes")
        ->check(CLI::IsMember({"i420", "nv12", "yuyv"}));
    sub->add_flag_callback(
        "--versus-i420", [&o] { o.versusYuv = "i420"; }, "The same as --versus-yuv i420");
    return sub;
}

/// The read and write subcommands' table: a row per number of threads (`labels`), the median of
/// its passes' ms per frame and its ratio to the first row's.
void printMedians(const std::vector<std::string>& labels, std::vector<std::vector<double>>& ms)
{
    std::printf("%-8s %14s %10s\n", "threads", "ms per frame", "ratio");
    double first = 0.0;
    for (std::size_t i = 0; i < labels.size(); ++i) {
        std::vector<double>& runs = ms[i];
        std::nth_element(runs.begin(), runs.begin() + static_cast<std::ptrdiff_t>(runs.size() / 2), runs.end());
        const double median = runs[runs.size() / 2];
        if (i == 0)
            first = median;
        std::printf("%-8s %14.2f %10.3f\n", labels[i].c_str(), median, median / first);
    }
}

/// The read and write subcommands' --threads (`what` threads, a list) and --passes.
void addThreadsAndPasses(CLI::App& sub, std::vector<std::size_t>& threads, int& passes, const std::string& what)
{
    sub.add_option("--threads", threads, what + " threads, comma-separated")
        ->delimiter(',')
        ->check(cli::between(1, 64))
        ->capture_default_str();
    sub.add_option("--passes", passes, "Timed passes per number of threads, interleaved")
        ->check(cli::between(1, 1000))
        ->capture_default_str();
}

/// `defocus-bench read`: what reading a recorded clip ahead of the filter costs per frame, as the
/// command line reads it (depth as stored, ReadAheadSource), on 1..N threads.
struct ReadOptions {
    std::string input = "data/tum_fr1_rpy";
    std::string depth;
    std::optional<double> depthScale;
    std::vector<std::size_t> threads{1, 2};
    int passes = 3;
};

CLI::App* declareRead(CLI::App& app, ReadOptions& o)
{
    CLI::App* sub = app.add_subcommand("read", "Milliseconds per frame of reading a recorded clip as the command "
                                               "line does (decoded ahead of the filter) on each number of threads, "
                                               "passes interleaved, the files in the page cache; median of the passes "
                                               "and its ratio to the first number's");
    sub->add_option("INPUT", o.input, "What `defocus INPUT` takes: a TUM folder, a folder of images, ...")
        ->capture_default_str();
    sub->add_option("--depth", o.depth, "Its --depth");
    sub->add_option("--depth-scale", o.depthScale, "Its --depth-scale");
    addThreadsAndPasses(*sub, o.threads, o.passes, "Reading");
    return sub;
}

int runRead(const ReadOptions& o)
{
    SourceOptions source;
    source.input = o.input;
    if (!o.depth.empty())
        source.depth = o.depth;
    source.depthScale = o.depthScale;
    source.depthUnits = true;
    // One pass unmeasured first: every number of threads then reads from the page cache.
    const auto readAll = [&](std::size_t threads) {
        const auto start = std::chrono::steady_clock::now();
        const auto ahead = ReadAheadSource::onThreads(openSource(source), threads);
        std::size_t frames = 0;
        while (ahead->next())
            ++frames;
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        return std::pair{frames, ms / static_cast<double>(std::max<std::size_t>(frames, 1))};
    };
    const std::size_t frames = readAll(1).first;
    std::vector<std::vector<double>> ms(o.threads.size());
    for (int pass = 0; pass < o.passes; ++pass)
        for (std::size_t i = 0; i < o.threads.size(); ++i)
            ms[i].push_back(readAll(o.threads[i]).second);
    std::printf("defocus-bench read: %s, %zu frames, %d passes, %u CPUs here, reading threads by default: %zu\n",
                o.input.c_str(), frames, o.passes, std::thread::hardware_concurrency(),
                ReadAheadSource::defaultThreads());
    std::vector<std::string> labels;
    for (const std::size_t threads : o.threads)
        labels.push_back(std::to_string(threads));
    printMedians(labels, ms);
    return 0;
}

/// `defocus-bench write`: what writing an output costs per frame, as the command line writes it (a
/// BackgroundSink over the sink): a folder (DIR/, PNG in the TUM layout) on 1..N threads, or a video.
struct WriteOptions {
    std::string input = "data/tum_fr1_rpy";
    std::string size;
    std::size_t frames = 24;
    std::vector<std::size_t> threads{1, 2};
    int passes = 3;
    std::string as = "folder";
};

CLI::App* declareWrite(CLI::App& app, WriteOptions& o)
{
    CLI::App* sub = app.add_subcommand("write", "Milliseconds per frame of writing an output as the command line "
                                                "does, from the filter's call to the finished output, into the "
                                                "system's temporary folder: a folder (PNG colour and 16-bit depth, "
                                                "the TUM layout) on each number of encoding threads, or a video "
                                                "(--as); passes interleaved; median of the passes and its ratio to "
                                                "the first number's");
    sub->add_option("INPUT", o.input, "A TUM folder whose frames (repeated as needed) are written")->capture_default_str();
    sub->add_option("--size", o.size, "Frame size WIDTHxHEIGHT [default: the clip's]");
    sub->add_option("--frames", o.frames, "Frames per pass")->check(cli::between(1, 100000))->capture_default_str();
    addThreadsAndPasses(*sub, o.threads, o.passes, "Encoding");
    sub->add_option("--as", o.as,
                    "The output: a folder, or a video with the container's default codec (colour only; its "
                    "encoder's own threads, --threads not used)")
        ->check(CLI::IsMember({"folder", "mp4", "mkv", "webm", "avi"}))
        ->capture_default_str();
    return sub;
}

int runWrite(const WriteOptions& o)
{
    SourceOptions source;
    source.input = o.input;
    source.depthUnits = true; // as the command line passes depth on: 16-bit, as stored
    std::vector<Frame> clip;
    for (auto frames = openSource(source); auto frame = frames->next();)
        clip.push_back(std::move(*frame));
    if (clip.empty())
        throw std::runtime_error(fmt::format("{} gave no frames", o.input));
    if (!o.size.empty())
        clip = resizeClip(clip, parseSize(o.size));
    const bool folder = o.as == "folder";
    const fs::path scratch = fs::temp_directory_path() / fmt::format("defocus-bench-write-{}", ::getpid());
    const std::vector<std::size_t> threadCounts = folder ? o.threads : std::vector<std::size_t>{1};
    const auto writeAll = [&](std::size_t threads) {
        fs::remove_all(scratch);
        SinkOptions options(folder ? scratch.string() + "/" : scratch.string() + "." + o.as);
        options.threads = threads;
        const auto start = std::chrono::steady_clock::now();
        BackgroundSink sink(openSink(options));
        for (std::size_t i = 0; i < o.frames; ++i) {
            Frame origin = clip[i % clip.size()];
            origin.index = i;
            origin.timestampS = 1.0 + static_cast<double>(i) / 30.0;
            origin.name = fmt::format("{:.6f}.png", origin.timestampS);
            sink.writeFrame(origin.color, origin);
        }
        sink.finish();
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        std::size_t files = 0;
        if (folder)
            for (const auto& entry : fs::recursive_directory_iterator(scratch))
                files += entry.path().extension() == ".png" ? 1 : 0;
        else
            files = fs::exists(options.output) && fs::file_size(options.output) > 0 ? 1 : 0;
        fs::remove_all(scratch);
        fs::remove(options.output);
        const std::size_t expected = folder ? 2 * o.frames : 1;
        if (sink.framesWritten() != o.frames || files != expected)
            throw std::runtime_error(fmt::format("{} threads wrote {} frames and {} files, not {} and {}", threads,
                                                 sink.framesWritten(), files, o.frames, expected));
        return ms / static_cast<double>(o.frames);
    };
    writeAll(threadCounts.front()); // unmeasured: the encoder's first use
    std::vector<std::vector<double>> ms(threadCounts.size());
    for (int pass = 0; pass < o.passes; ++pass)
        for (std::size_t i = 0; i < threadCounts.size(); ++i)
            ms[i].push_back(writeAll(threadCounts[i]));
    std::printf("defocus-bench write: %s at %dx%d as %s, %zu frames, %d passes, %u CPUs here, encoding threads by "
                "default: %s\n",
                o.input.c_str(), clip.front().color.cols, clip.front().color.rows, o.as.c_str(), o.frames, o.passes,
                std::thread::hardware_concurrency(),
                folder ? std::to_string(ReadAheadSource::defaultThreads()).c_str() : "the encoder's");
    std::vector<std::string> labels;
    for (const std::size_t threads : threadCounts)
        labels.push_back(folder ? std::to_string(threads) : "encoder's");
    printMedians(labels, ms);
    return 0;
}

/// `defocus-bench accuracy ...` runs the accuracy sweep, built as its own program beside this one,
/// with the arguments after the subcommand (its --help included).
int runAccuracy(const std::vector<std::string>& rest, const char* self)
{
    const std::string program = (std::filesystem::path(self).parent_path() / "defocus-bench-accuracy").string();
    std::vector<std::string> all{program};
    all.insert(all.end(), rest.begin(), rest.end());
    std::vector<char*> args;
    for (auto& arg : all)
        args.push_back(arg.data());
    args.push_back(nullptr);
    execv(program.c_str(), args.data());
    std::fprintf(stderr, "defocus-bench: error: accuracy: cannot run '%s'\n", program.c_str());
    return kExitBadInput;
}

} // namespace

int main(int argc, char** argv)
{
    Options o;
    CLI::App app{"defocus-bench: milliseconds per pass and per frame of the defocus pipeline on the bundled TUM "
                 "clip, resized to each size; median and p90 of several runs, for a defocused and an all-in-focus "
                 "scene. Run it from the repository root. The subcommands time the per-frame plan (plan), hold the "
                 "per-pass timing baseline (timing), time frames in flight against one at a time (throughput), time reading a clip ahead of the filter (read) and writing a folder output behind it (write), and sweep accuracy against a path-traced lens (accuracy); "
                 "each has its own --help."};
    defocus::cli::addVersionFlag(app, "defocus-bench");
    app.require_subcommand(0, 1);
    defocus::TimingOptions timingOptions;
    CLI::App* timing = declareTiming(app, timingOptions);
    defocus::PlanOptions planOptions;
    CLI::App* plan = declarePlan(app, planOptions);
    defocus::ThroughputOptions throughputOptions;
    CLI::App* throughput = declareThroughput(app, throughputOptions);
    ReadOptions readOptions;
    CLI::App* read = declareRead(app, readOptions);
    WriteOptions writeOptions;
    CLI::App* write = declareWrite(app, writeOptions);
    CLI::App* accuracy = app.add_subcommand("accuracy", "Error against a path-traced thin lens and time per frame of "
                                                        "every method (defocus-bench-accuracy; 'accuracy --help' "
                                                        "lists its options)");
    accuracy->prefix_command();
    accuracy->set_help_flag(); // its --help is defocus-bench-accuracy's
    app.add_option("--data", o.data, "TUM RGB-D folder to take frames from")->capture_default_str();
    app.add_option("--sizes", o.sizes, "Frame sizes WIDTHxHEIGHT, comma-separated")
        ->delimiter(',')
        ->capture_default_str();
    app.add_option("--runs", o.runs, "Measured frames per size and scene")
        ->check(cli::between(1, 100000))
        ->capture_default_str();
    app.add_option("--warmup", o.warmup, "Unmeasured frames first, per size and scene")
        ->check(cli::between(0, 1000))
        ->capture_default_str();
    cli::addQualityOptions(app, o.quality, o);
    app.add_flag("--quarter-on-large-blur", o.quarterOnLargeBlur,
                 "Half size goes to quarter size on frames whose blur is mostly beyond 32 px and that have no "
                 "bokeh sprites (off in the presets: docs/benchmarks.md)");
    auto* halfOnly = app.add_flag("--versus-half-only", o.versusHalfOnly,
                 "Also time the defocused scene always at half size (quarter size on large blur off: the path "
                 "before it), frames alternating with the main settings', and print the ratio of frame times");
    auto* cpuPrep = app.add_flag("--versus-cpu-prep", o.versusCpuPrep,
                 "Depth prep and the scene measurement on the GPU (the default but on software renderers), and "
                 "also the defocused scene with them on the CPU (the filled depth uploaded), frames alternating "
                 "with the GPU's, and print the ratio of frame times")
        ->excludes(halfOnly);
    app.add_flag("--versus-fragment", o.versusFragment,
                 "The passes as compute shaders (the default but on software renderers), and also the defocused "
                 "scene with them drawn by their fragment shaders, frames alternating with the compute ones', and "
                 "print the ratio of frame times")
        ->excludes(halfOnly)
        ->excludes(cpuPrep);
    app.add_flag("--finish-each-pass", o.finishEachPass,
                 "Profiling: glFinish before and after each pass, and wall ms per pass instead of timer queries "
                 "(llvmpipe renders at a flush, so its queries need not fall on the pass that was issued)");
    app.add_option("--focus", o.focusM, "Distance in focus, metres")->capture_default_str();
    app.add_option("--f-number", o.fNumber, "Aperture as an f-number")->capture_default_str();
    app.add_option("--focal-length", o.focalLengthMm, "Focal length, millimetres")->capture_default_str();
    app.add_option("--max-coc", o.maxCocAt640, "Largest blur diameter in pixels at 640 px wide; scaled by width/640")
        ->capture_default_str();
    app.add_option("--blades", o.blades, "Aperture blades: 0 = a circular aperture, else the polygon's corners, 3 to 16")
        ->capture_default_str();
    app.add_option("--blade-rotation", o.bladeRotationDeg, "Aperture rotation, degrees counter-clockwise (as defocus)")
        ->capture_default_str();
    app.add_option("--aperture-ratio", o.apertureRatio, "Anamorphic squeeze of the aperture (as defocus)")
        ->capture_default_str();
    app.add_flag("--no-adaptive", o.noAdaptive,
                 "Run every pass on every pixel (no skipping of in-focus frames and tiles), for comparison");
    app.add_flag("--no-timers", o.noTimers, "Leave GL timer queries off, to see what timing the passes costs");
    app.add_option("--json", o.json, "Also write every run, the GL renderer and the date to this JSON file");

    if (const auto status = cli::parse(app, argc, argv))
        return *status;
    cli::logToStderr("defocus-bench");
    cli::finishQuality(app, o, o.quality);
    spdlog::set_level(spdlog::level::warn); // keep the library's info lines out of the table

    try {
        if (accuracy->parsed())
            return runAccuracy(accuracy->remaining(), argv[0]);
        if (timing->parsed())
            return defocus::runTimingComparison(timingOptions);
        if (plan->parsed())
            return defocus::runPlanComparison(planOptions);
        if (throughput->parsed())
            return defocus::runThroughput(throughputOptions);
        if (read->parsed())
            return runRead(readOptions);
        if (write->parsed())
            return runWrite(writeOptions);
        std::string commandLine = "defocus-bench";
        for (int i = 1; i < argc; ++i)
            commandLine += std::string(" ") + argv[i];
        return run(o, commandLine);
    } catch (const CLI::ValidationError& error) {
        spdlog::error("{}", error.what());
        return kExitUsage;
    } catch (const std::exception& error) {
        spdlog::error("{}", error.what());
        return bench::statusFor(error);
    }
}
