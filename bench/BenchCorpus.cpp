// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-bench accuracy --scene DIR: the presets measured on a corpus of scene folders.
#include "bench/BenchCorpus.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/Metrics.hpp"
#include "bench/methods/Method.hpp"
#include "bench/methods/Presets.hpp"
#include "filter/DepthPrep.hpp"
#include "filter/Lens.hpp"
#include "filter/Presets.hpp"
#include "filter/gl/EglContext.hpp"
#include "samples/BenchMachine.hpp"
#include "sources/AccuracyScene.hpp"
#include "sources/ImageIO.hpp"

namespace defocus {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

/// The anchors: other tools' output for the same scene, made by scripts/corpus/anchors.sh.
constexpr const char* kAnchors[] = {"blender-defocus", "gegl-lens-blur"};

struct Measured {
    std::string what; ///< "input", a preset's name or an anchor's
    ErrorReport error;
    ZoneReport zones;
    double wallMs = std::nan("");
};

struct SceneResult {
    AccuracyScene scene;
    double maxCocPx = 0.0;
    std::vector<Measured> rows;
    const Measured* find(const std::string& what) const
    {
        for (const Measured& m : rows)
            if (m.what == what)
                return &m;
        return nullptr;
    }
};

std::string db(double value)
{
    return std::isnan(value) ? "-" : std::isinf(value) ? "inf" : fmt::format("{:.2f}", value);
}

Json jsonNumber(double value)
{
    return std::isfinite(value) ? Json(value) : Json(nullptr);
}

Json measuredJson(const Measured& m)
{
    Json zones = Json::object();
    for (const Zone zone : kZones) {
        const auto i = static_cast<std::size_t>(zone);
        zones[std::string(zoneName(zone))] = {{"psnrLinearDb", jsonNumber(m.zones.psnr[i])},
                                              {"pixelShare", m.zones.share[i]},
                                              {"errorShare", m.zones.errorShare[i]}};
    }
    return {{"what", m.what},
            {"psnrLinearDb", jsonNumber(m.error.psnrLinear)},
            {"psnrSrgbDb", jsonNumber(m.error.psnrSrgb)},
            {"ssim", jsonNumber(m.error.ssim)},
            {"wallMs", jsonNumber(m.wallMs)},
            {"zones", zones}};
}

} // namespace

int runCorpusAccuracy(const CorpusOptions& options, const std::string& commandLine)
{
    std::vector<fs::path> dirs;
    for (const std::string& path : options.scenes) {
        std::error_code ec;
        if (!fs::exists(path, ec) && options.missingOk) {
            fmt::print("defocus-bench accuracy: skipped: scene folder '{}' does not exist\n", path);
            return 77;
        }
        for (const fs::path& dir : findAccuracyScenes(path))
            dirs.push_back(dir);
    }
    struct Chosen {
        std::string label; ///< the preset's name, or NAME:half-only
        Preset preset;
    };
    std::vector<Chosen> chosen;
    if (options.presets.empty())
        for (const Preset& preset : presets())
            chosen.push_back({std::string(preset.name), preset});
    for (const std::string& label : options.presets) {
        // NAME, then any of :quarter, :half-only, :no-sprites, :16f and :32f.
        std::string_view name = label;
        bool quarter = false, halfOnly = false, noSprites = false, half = false, full = false;
        for (bool found = true; found;) {
            found = false;
            for (const auto& [suffix, flag] : {std::pair<std::string_view, bool*>{":quarter", &quarter},
                                               std::pair<std::string_view, bool*>{":half-only", &halfOnly},
                                               std::pair<std::string_view, bool*>{":no-sprites", &noSprites},
                                               std::pair<std::string_view, bool*>{":16f", &half},
                                               std::pair<std::string_view, bool*>{":32f", &full}})
                if (name.ends_with(suffix)) {
                    name.remove_suffix(suffix.size());
                    *flag = found = true;
                }
        }
        Preset p = preset(name); // throws, naming the presets there are
        if (quarter || halfOnly)
            p.settings.quarterOnLargeBlur = quarter && !halfOnly;
        if (noSprites)
            p.settings.highlightSprites = false;
        if (half || full)
            p.settings.precision = half ? TargetFormat::Rgba16F : TargetFormat::Rgba32F;
        chosen.push_back({label, p});
    }
    // Every scene is read and checked before the first is measured: a bad folder fails at once.
    std::vector<AccuracyScene> scenes;
    for (const fs::path& dir : dirs)
        scenes.push_back(loadAccuracyScene(dir));

    gl::EglContext context = gl::EglContext::create();
    fmt::print("defocus-bench accuracy, {}; {} scene(s); GL renderer {}\ncommand: {}\n", utcNow(), scenes.size(),
               context.info().glRenderer, commandLine);
    fmt::print("measure: linear PSNR clipped to [0,1] against each scene's thin-lens truth; zones (bench/Metrics.hpp): "
               "lights = within 30 px of an input pixel above white, then depth edges, in focus, near, far\n");

    std::map<std::string, std::unique_ptr<Method>> methods;
    std::vector<SceneResult> results;
    for (const AccuracyScene& scene : scenes) {
        AccuracyImages images = readAccuracyImages(scene);
        if (options.scale != 1) {
            const cv::Size size = images.color.size() * options.scale;
            cv::resize(images.color, images.color, size, 0, 0, cv::INTER_LINEAR);
            cv::resize(images.truth, images.truth, size, 0, 0, cv::INTER_LINEAR);
            cv::resize(images.depth, images.depth, size, 0, 0, cv::INTER_NEAREST);
        }
        SceneResult result{scene, 0.0, {}};
        LensSettings lens = scene.lens;
        // max-coc from the scene: the largest CoC of its depth, so that nothing is clamped (the
        // truth clamps nothing either).
        lens.maxCocPx = 512.0;
        const cv::Mat coc = cocMap(prepareDepth(images.depth, images.color.size(), static_cast<float>(lens.focusM)).metres,
                                   cocCoefficients(lens, images.color.cols));
        double lo = 0.0, hi = 0.0;
        cv::minMaxLoc(coc, &lo, &hi);
        lens.maxCocPx = std::clamp(std::ceil(std::max(std::abs(lo), std::abs(hi))) + 1.0, 8.0, 512.0);
        result.maxCocPx = lens.maxCocPx;
        const cv::Mat regions = regionMap(coc);
        const cv::Mat zones = zoneMap(images.color, coc);
        const auto measure = [&](const std::string& what, const cv::Mat& image, double wallMs) {
            result.rows.push_back({what, measureError(image, images.truth, regions),
                                   measureZones(image, images.truth, zones), wallMs});
        };
        measure("input", images.color, std::nan(""));
        const Frame frame{images.color, images.depth, 0.0, 0, scene.name};
        for (const auto& [label, preset] : chosen) {
            auto& method = methods[std::string(preset.method)];
            if (!method)
                method = createMethod(preset.method, false);
            const MethodResult out = method->run(frame, lens, preset.settings);
            measure(label, out.linear, out.wallMs);
            if (options.saveOutputs) {
                const fs::path file = fs::path(options.out) / "outputs" / scene.name / fmt::format("{}.exr", label);
                fs::create_directories(file.parent_path());
                if (!cv::imwrite(file.string(), out.linear))
                    throw std::runtime_error(fmt::format("cannot write {}", file.string()));
            }
        }
        if (!options.anchors.empty())
            for (const char* anchor : kAnchors) {
                const fs::path file = fs::path(options.anchors) / scene.name / fmt::format("{}.exr", anchor);
                std::error_code ec;
                if (!fs::is_regular_file(file, ec))
                    continue;
                cv::Mat image = readColor(file);
                if (image.size() != images.color.size())
                    throw std::runtime_error(fmt::format("{}: {}x{}, the scene is {}x{}", file.string(), image.cols,
                                                         image.rows, images.color.cols, images.color.rows));
                measure(anchor, image, std::nan(""));
            }
        fmt::print(stderr, "defocus-bench accuracy: {} measured\n", scene.name);
        results.push_back(std::move(result));
    }

    // The per-scene table.
    std::vector<std::string> columns{"input"};
    for (const Chosen& c : chosen)
        columns.push_back(c.label);
    if (!options.anchors.empty())
        for (const char* anchor : kAnchors)
            columns.emplace_back(anchor);
    fmt::print("\nlinear PSNR, dB\n{:<22}", "scene");
    for (const std::string& c : columns)
        fmt::print("{:>17}", c);
    fmt::print("{:>10}{:>9}\n", "max-coc", "truth");
    for (const SceneResult& r : results) {
        fmt::print("{:<22}", r.scene.name);
        for (const std::string& c : columns) {
            const Measured* m = r.find(c);
            fmt::print("{:>17}", m ? db(m->error.psnrLinear) : "-");
        }
        fmt::print("{:>10.0f}{:>9}\n", r.maxCocPx, db(r.scene.truthEstimatedPsnrDb));
    }
    // Minimum and median over the corpus, per column (scenes without the column left out).
    Json summary = Json::object();
    for (const char* statistic : {"min", "median"}) {
        fmt::print("{:<22}", statistic);
        for (const std::string& c : columns) {
            std::vector<double> values;
            for (const SceneResult& r : results)
                if (const Measured* m = r.find(c))
                    values.push_back(m->error.psnrLinear);
            const double value = values.empty()                  ? std::nan("")
                                 : std::string(statistic) == "min" ? *std::min_element(values.begin(), values.end())
                                                                   : median(values);
            summary[c][statistic] = jsonNumber(value);
            summary[c]["scenes"] = values.size();
            fmt::print("{:>17}", db(value));
        }
        fmt::print("\n");
    }
    // Per zone: PSNR and the share of the squared error, for every measured row.
    fmt::print("\nper zone: PSNR dB (share of the squared error)\n{:<22}{:<17}", "scene", "what");
    for (const Zone zone : kZones)
        fmt::print("{:>19}", zoneName(zone));
    fmt::print("\n");
    for (const SceneResult& r : results) {
        fmt::print("{:<22}{:<17}", r.scene.name, "(pixels)");
        for (const Zone zone : kZones)
            fmt::print("{:>18.1f}%", 100.0 * r.rows.front().zones.share[static_cast<std::size_t>(zone)]);
        fmt::print("\n");
        for (const Measured& m : r.rows) {
            if (m.what == "input")
                continue;
            fmt::print("{:<22}{:<17}", "", m.what);
            for (const Zone zone : kZones) {
                const auto i = static_cast<std::size_t>(zone);
                fmt::print("{:>19}", fmt::format("{} ({:.0f}%)", db(m.zones.psnr[i]), 100.0 * m.zones.errorShare[i]));
            }
            fmt::print("\n");
        }
    }

    // Files.
    const fs::path out = options.out;
    fs::create_directories(out);
    Json json;
    json["tool"] = "defocus-bench accuracy";
    json["date"] = utcNow();
    json["command"] = commandLine;
    json["glRenderer"] = context.info().glRenderer;
    Json list = Json::array();
    for (const SceneResult& r : results) {
        Json rows = Json::array();
        for (const Measured& m : r.rows)
            rows.push_back(measuredJson(m));
        list.push_back({{"scene", r.scene.name},
                        {"dir", r.scene.dir.string()},
                        {"description", r.scene.description},
                        {"lens",
                         {{"focalLengthMm", r.scene.lens.focalLengthMm},
                          {"sensorWidthMm", r.scene.lens.sensorWidthMm},
                          {"fNumber", r.scene.lens.fNumber},
                          {"focusM", r.scene.lens.focusM},
                          {"bladeRotationDeg", r.scene.lens.bladeRotationDeg},
                          {"fieldOfView", fieldOfViewName(r.scene.lens.fieldOfView)},
                          {"maxCocPx", r.maxCocPx}}},
                        {"truthEstimatedPsnrDb", jsonNumber(r.scene.truthEstimatedPsnrDb)},
                        {"results", rows}});
    }
    json["scenes"] = list;
    json["summary"] = summary;
    const fs::path jsonFile = out / "corpus.json", csvFile = out / "corpus.csv";
    {
        std::ofstream file(jsonFile);
        file << json.dump(2) << "\n";
        if (!file)
            throw std::runtime_error(fmt::format("cannot write {}", jsonFile.string()));
    }
    {
        std::ofstream file(csvFile);
        file << "scene,what,psnr_linear_db,psnr_srgb_db,ssim";
        for (const Zone zone : kZones)
            file << fmt::format(",{0}_db,{0}_pixel_share,{0}_error_share", zoneName(zone));
        file << "\n";
        for (const SceneResult& r : results)
            for (const Measured& m : r.rows) {
                file << fmt::format("{},{},{:.3f},{:.3f},{:.5f}", r.scene.name, m.what, m.error.psnrLinear,
                                    m.error.psnrSrgb, m.error.ssim);
                for (const Zone zone : kZones) {
                    const auto i = static_cast<std::size_t>(zone);
                    file << fmt::format(",{:.3f},{:.4f},{:.4f}", m.zones.psnr[i], m.zones.share[i],
                                        m.zones.errorShare[i]);
                }
                file << "\n";
            }
        if (!file)
            throw std::runtime_error(fmt::format("cannot write {}", csvFile.string()));
    }
    fmt::print("\nwrote {} and {}\n", jsonFile.string(), csvFile.string());
    return 0;
}

} // namespace defocus
