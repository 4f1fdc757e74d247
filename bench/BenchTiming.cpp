// SPDX-License-Identifier: LGPL-2.1-or-later
// Timing baseline and comparator: medians of each preset's frame wall time and per-pass GPU time
// over a calibration pass's, measured interleaved in one run.
#include "bench/BenchTiming.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench/passes/CalibrationPass.hpp"
#include "filter/Pipeline.hpp"
#include "filter/Presets.hpp"
#include "filter/gl/EglContext.hpp"
#include "filter/gl/GpuTimer.hpp"
#include "samples/BenchMachine.hpp"
#include "samples/ExitStatus.hpp"
#include "sources/FrameSource.hpp"

namespace defocus {

namespace {

/// The calibration pass: a fixed 16-tap blur of the frame's colour into a target of its own,
/// timed as a frame is: GPU time by its own timer query, wall time up to its pixels read back.
class Calibration {
public:
    explicit Calibration(const Frame& frame)
        : size_(frame.color.size()),
          input_(GL_SRGB8, size_.width, size_.height, "calibration input"),
          output_(GL_RGBA16F, size_.width, size_.height, "calibration output"),
          target_(output_, "calibration output"),
          vao_(gl::VertexArray::create()),
          pixels_(static_cast<std::size_t>(size_.area()) * 4)
    {
        input_.upload(GL_BGR, GL_UNSIGNED_BYTE, frame.color.data);
    }

    /// Runs the pass once; returns its wall time, ms. Its GPU time arrives with gpuMs().
    double run()
    {
        const auto start = std::chrono::steady_clock::now();
        glBindVertexArray(vao_.id());
        timer_.begin(CalibrationPass::kName);
        pass_.run(input_, target_);
        timer_.end();
        glBindFramebuffer(GL_READ_FRAMEBUFFER, target_.id());
        glReadPixels(0, 0, size_.width, size_.height, GL_RGBA, GL_UNSIGNED_BYTE, pixels_.data());
        const auto end = std::chrono::steady_clock::now();
        for (const auto& [name, ms] : timer_.swap())
            gpuMs_.push_back(ms);
        return std::chrono::duration<double, std::milli>(end - start).count();
    }
    std::vector<double>& gpuMs() { return gpuMs_; }

private:
    cv::Size size_;
    CalibrationPass pass_;
    gl::Texture input_;
    gl::Texture output_;
    gl::Framebuffer target_;
    gl::VertexArray vao_;
    gl::GpuTimer timer_;
    std::vector<unsigned char> pixels_;
    std::vector<double> gpuMs_;
};

/// One preset's medians over `runs` frames, the calibration's interleaved with them.
nlohmann::json timePreset(const std::string& preset, const std::vector<Frame>& frames, const LensSettings& lens,
                          int runs, int& allInFocusFrames)
{
    Pipeline pipeline;
    Calibration calibration(frames.front());
    const QualitySettings quality = presetSettings(preset);
    std::vector<double> calibrationWall, frameWall;
    std::map<std::string, std::vector<double>> passMs;
    for (int run = 0; run < runs + 1; ++run) { // run 0 warms up (shaders, targets)
        const double calibrationMs = calibration.run();
        pipeline.run(frames[static_cast<std::size_t>(run) % frames.size()], lens, quality);
        if (run == 0)
            continue;
        calibrationWall.push_back(calibrationMs);
        frameWall.push_back(pipeline.timings().totalMs); // process() + read(), wall clock
        allInFocusFrames += pipeline.plan().allInFocus ? 1 : 0;
        for (const auto& pass : pipeline.timings().gpu) // the previous frame's, read one frame late
            passMs[pass.name].push_back(pass.ms);
    }
    for (const auto& pass : pipeline.drainGpuTimes())
        passMs[pass.name].push_back(pass.ms);
    calibration.run(); // collects the last calibration query
    calibration.gpuMs().erase(calibration.gpuMs().begin()); // run 0's, the warm-up

    const double calibrationWallMs = median(calibrationWall);
    const double calibrationGpuMs = median(calibration.gpuMs());
    nlohmann::json result{{"calibration_wall_ms", calibrationWallMs},
                          {"calibration_gpu_ms", calibrationGpuMs},
                          {"frame_ms", median(frameWall)},
                          {"frame_ratio", median(frameWall) / calibrationWallMs},
                          {"passes", nlohmann::json::object()}};
    for (const auto& [name, v] : passMs)
        result["passes"][name] = {{"ms", median(v)}, {"ratio", median(v) / calibrationGpuMs}};
    return result;
}

} // namespace

int runTimingComparison(const TimingOptions& options)
{
    if (!std::filesystem::exists(options.data)) {
        std::fprintf(stderr, "defocus-bench timing: data '%s' not found (run from the repository root or pass --data)\n",
                     options.data.c_str());
        return kExitBadInput;
    }
    nlohmann::json baseline;
    if (!options.baseline.empty()) {
        std::ifstream in(options.baseline);
        try {
            if (!in)
                throw std::runtime_error("cannot open it");
            in >> baseline;
            if (!baseline.contains("presets") || !baseline["presets"].is_object())
                throw std::runtime_error("no \"presets\" object (a baseline of an older defocus-bench?)");
        } catch (const std::exception& error) {
            std::fprintf(stderr, "defocus-bench timing: cannot read baseline '%s': %s\n", options.baseline.c_str(),
                         error.what());
            return kExitBadInput;
        }
    }
    auto context = gl::EglContext::create();
    if (!context.info().timerQueries) {
        std::fprintf(stderr, "defocus-bench timing: %s has no GPU timer queries\n", context.info().glRenderer.c_str());
        return kExitUnavailable;
    }
    auto source = openSource({options.data, std::nullopt, std::nullopt});
    std::vector<Frame> frames;
    while (auto frame = source->next())
        if (frames.size() < 3)
            frames.push_back(std::move(*frame));
    if (frames.empty()) {
        std::fprintf(stderr, "defocus-bench timing: '%s' gave no frames\n", options.data.c_str());
        return kExitBadInput;
    }

    LensSettings lens;
    lens.focusM = 1.0;
    lens.fNumber = options.fNumber;
    lens.maxCocPx = options.maxCocPx;
    std::vector<std::string> presetNames = options.presets;
    if (presetNames.empty())
        for (const QualityPreset& p : qualityPresets())
            presetNames.emplace_back(p.name);

    const cv::Size size = frames.front().color.size();
    nlohmann::json result{{"renderer", context.info().glRenderer},
                          {"width", size.width},
                          {"height", size.height},
                          {"runs", options.runs},
                          {"date", utcNow()},
                          {"presets", nlohmann::json::object()}};
    std::printf("defocus-bench timing on %s, %dx%d, %d runs per preset, f/%g, max-coc %g px\n",
                context.info().glRenderer.c_str(), size.width, size.height, options.runs, options.fNumber,
                options.maxCocPx);
    int allInFocus = 0;
    for (const auto& name : presetNames)
        result["presets"][name] = timePreset(name, frames, lens, options.runs, allInFocus);

    if (!options.writeBaseline.empty()) {
        std::ofstream(options.writeBaseline) << result.dump(2) << "\n";
        std::printf("wrote baseline %s\n", options.writeBaseline.c_str());
    }

    // The table: each preset's frame, then its passes; with a baseline, the change and the verdict.
    int failures = 0;
    std::vector<std::string> reasons;
    const auto fail = [&](const std::string& reason) {
        ++failures;
        reasons.push_back(reason);
        return "  " + reason;
    };
    std::printf("  %-22s %9s %8s %8s %8s  (frame: wall incl. readback / calibration wall, limit %.2fx the "
                "baseline; pass: GPU / calibration GPU)\n",
                "preset / pass", "ms", "ratio", "baseline", "change", options.maxRatio);
    // Frames are held to the limit; a pass's ratio is printed beside its baseline to show where a
    // frame's time went (GPU timer queries on a shared machine are too noisy to fail on alone).
    const auto row = [&](const std::string& label, double ms, double ratio, const nlohmann::json* then,
                         const std::string& what, bool held) {
        if (!then) {
            std::printf("  %-22s %9.2f %8.3f\n", label.c_str(), ms, ratio);
            return;
        }
        const double before = then->at("ratio").get<double>();
        const double change = ratio / std::max(before, 1e-9);
        std::string verdict;
        if (held && change > options.maxRatio)
            verdict = fail(fmt::format("REGRESSION: {} {:.2f}x its baseline ratio", what, change));
        std::printf("  %-22s %9.2f %8.3f %8.3f %7.2fx%s\n", label.c_str(), ms, ratio, before, change, verdict.c_str());
    };
    for (const auto& [name, preset] : result["presets"].items()) {
        const bool compared = !baseline.is_null();
        const nlohmann::json* then = compared && baseline["presets"].contains(name) ? &baseline["presets"][name] : nullptr;
        if (compared && !then)
            std::printf("  %s\n", fail(fmt::format("MISSING: --quality {} has no baseline", name)).c_str());
        nlohmann::json frameThen;
        if (then)
            frameThen = {{"ratio", then->at("frame_ratio")}};
        row(name + " frame", preset["frame_ms"].get<double>(), preset["frame_ratio"].get<double>(),
            then ? &frameThen : nullptr, "--quality " + name + " frame", true);
        for (const auto& [pass, timed] : preset["passes"].items()) {
            const bool known = then && then->at("passes").contains(pass);
            if (then && !known)
                std::printf("  %s\n", fail(fmt::format("RENAMED: pass {} of --quality {} is not in the baseline",
                                                       pass, name)).c_str());
            row("  " + pass, timed["ms"].get<double>(), timed["ratio"].get<double>(),
                known ? &then->at("passes").at(pass) : nullptr, "pass " + pass + " of --quality " + name, false);
        }
        if (then)
            for (const auto& [pass, ignored] : then->at("passes").items())
                if (!preset["passes"].contains(pass))
                    std::printf("  %s\n", fail(fmt::format("MISSING: pass {} of --quality {} did not run", pass,
                                                           name)).c_str());
    }
    if (!baseline.is_null())
        for (const auto& [name, ignored] : baseline["presets"].items())
            if (!result["presets"].contains(name))
                std::printf("  %s\n", fail(fmt::format("MISSING: --quality {} of the baseline was not timed", name)).c_str());
    // A frame passed through as all in focus runs no pass: its time says nothing about the passes.
    if (allInFocus > 0)
        std::printf("  %s\n", fail(fmt::format("ALL IN FOCUS: {} timed frames ran no pass; choose a lens that blurs",
                                               allInFocus)).c_str());
    if (baseline.is_null() && allInFocus == 0)
        return 0;
    std::printf("%s\n", failures == 0 ? "timing: within bounds" : "timing: FAILED");
    return failures == 0 ? 0 : 1;
}

} // namespace defocus
