// Timing baseline and comparator: medians of per-pass GPU time over a calibration pass.
#include "samples/BenchTiming.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "filter/Pipeline.hpp"
#include "filter/gl/EglContext.hpp"
#include "filter/gl/GpuTimer.hpp"
#include "filter/methods/Presets.hpp"
#include "filter/passes/CalibrationPass.hpp"
#include "samples/BenchMachine.hpp"
#include "sources/FrameSource.hpp"

#include "samples/ExitStatus.hpp"

namespace defocus {

int runTimingComparison(const TimingOptions& options)
{
    if (!std::filesystem::exists(options.data)) {
        std::fprintf(stderr, "defocus-bench timing: data '%s' not found (run from the repository root or pass --data)\n",
                     options.data.c_str());
        return kExitBadInput;
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

    Pipeline pipeline;
    LensSettings lens;
    lens.focusM = 1.0;
    lens.fNumber = 1.4;
    const QualitySettings quality = presetSettings(options.preset);

    // The calibration pass blurs the frame's colour into a target of its own, timed with its own
    // queries, interleaved with the pipeline's frames.
    CalibrationPass calibration;
    const cv::Size size = frames.front().color.size();
    gl::Texture input(GL_SRGB8, size.width, size.height, "calibration input");
    input.upload(GL_BGR, GL_UNSIGNED_BYTE, frames.front().color.data);
    gl::Texture output(GL_RGBA16F, size.width, size.height, "calibration output");
    gl::Framebuffer target(output, "calibration output");
    auto vao = gl::VertexArray::create();
    gl::GpuTimer timer;

    std::map<std::string, std::vector<double>> passMs;
    std::vector<double> calibrationMs;
    for (int run = 0; run < options.runs + 1; ++run) {
        glBindVertexArray(vao.id());
        timer.begin(CalibrationPass::kName);
        calibration.run(input, target);
        timer.end();
        for (const auto& [name, ms] : timer.swap())
            if (run > 0)
                calibrationMs.push_back(ms);
        pipeline.run(frames[static_cast<std::size_t>(run) % frames.size()], lens, quality);
        if (run > 0) // the first frame's queries are read on the second
            for (const auto& pass : pipeline.timings().gpu)
                passMs[pass.name].push_back(pass.ms);
    }
    const double calibrationMedian = median(calibrationMs);
    nlohmann::json result{{"renderer", context.info().glRenderer},
                          {"width", size.width},
                          {"height", size.height},
                          {"preset", options.preset},
                          {"calibration_ms", calibrationMedian},
                          {"passes", nlohmann::json::object()}};
    std::printf("defocus-bench timing on %s, %dx%d, --quality %s, %d runs; calibration pass %.2f ms\n",
                context.info().glRenderer.c_str(), size.width, size.height, options.preset.c_str(), options.runs,
                calibrationMedian);
    for (const auto& [name, v] : passMs)
        result["passes"][name] = {{"ms", median(v)}, {"ratio", median(v) / calibrationMedian}};

    if (!options.writeBaseline.empty()) {
        std::ofstream(options.writeBaseline) << result.dump(2) << "\n";
        std::printf("wrote baseline %s\n", options.writeBaseline.c_str());
    }
    if (options.baseline.empty()) {
        for (const auto& [name, pass] : result["passes"].items())
            std::printf("  %-12s %8.2f ms  ratio %.2f\n", name.c_str(), pass["ms"].get<double>(),
                        pass["ratio"].get<double>());
        return 0;
    }

    std::ifstream in(options.baseline);
    nlohmann::json baseline;
    try {
        in >> baseline;
    } catch (const nlohmann::json::exception& error) {
        std::fprintf(stderr, "defocus-bench timing: cannot read baseline '%s': %s\n", options.baseline.c_str(),
                     error.what());
        return kExitBadInput;
    }
    if (const auto timed = baseline.value("preset", std::string("(not recorded)")); timed != options.preset)
        std::printf("note: the baseline timed --quality %s, this run --quality %s\n", timed.c_str(),
                    options.preset.c_str());
    int regressions = 0;
    std::printf("  %-12s %8s %8s %8s  (ratio = pass / calibration; limit %.2fx the baseline)\n", "pass", "ratio",
                "baseline", "change", options.maxRatio);
    for (const auto& [name, pass] : result["passes"].items()) {
        if (!baseline["passes"].contains(name)) {
            std::printf("  %-12s %8.2f %8s\n", name.c_str(), pass["ratio"].get<double>(), "new");
            continue;
        }
        const double now = pass["ratio"].get<double>();
        const double then = baseline["passes"][name]["ratio"].get<double>();
        const double change = now / std::max(then, 1e-9);
        const bool bad = change > options.maxRatio;
        regressions += bad ? 1 : 0;
        std::printf("  %-12s %8.2f %8.2f %7.2fx%s\n", name.c_str(), now, then, change, bad ? "  REGRESSION" : "");
    }
    std::printf("%s\n", regressions == 0 ? "timing: within bounds" : "timing: regression");
    return regressions == 0 ? 0 : 1;
}

} // namespace defocus
