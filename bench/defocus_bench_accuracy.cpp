// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-bench-accuracy: what accuracy costs in time. Runs every method of the registry at every
// knob setting on the Blender spheres scene (path-traced thin-lens truth), measures the error
// (PSNR linear and sRGB, SSIM, PSNR per region) and the time (GPU per pass, wall per frame, median
// of the runs after warm-up) in one run, and writes a table, CSV, JSON, a Pareto plot and a
// contact sheet of crops. A benchmark, not a test; docs/accuracy.md shows its output.
//   defocus-bench-accuracy                               (run from the repository root)
//   defocus-bench-accuracy --runs 9 -o out/accuracy --methods mcintosh,riguer
//   defocus-bench accuracy --scene data/blender_spheres --scene data/corpus   (presets on a corpus,
//       per scene and per zone, min and median: bench/BenchCorpus.cpp)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/BenchCli.hpp"
#include "bench/BenchCorpus.hpp"
#include "bench/Metrics.hpp"
#include "bench/methods/Method.hpp"
#include "bench/methods/Presets.hpp"
#include "filter/ColorSpace.hpp"
#include "filter/DepthPrep.hpp"
#include "filter/Lens.hpp"
#include "filter/Presets.hpp"
#include "filter/Views.hpp"
#include "filter/gl/EglContext.hpp"
#include "samples/BenchMachine.hpp"
#include "samples/CliOptions.hpp"
#include "samples/ExitStatus.hpp"
#include "sources/ImageIO.hpp"
#include "sources/SyntheticScene.hpp"

namespace {

using namespace defocus;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

/// Exit codes: 0 done, 1 runtime failure (data, GL, output), 2 bad command line.

struct Options {
    std::string data = "data/blender_spheres";
    std::string out = "out/accuracy";
    int runs = 7;
    int warmup = 2;
    std::vector<std::string> methods; ///< empty: all
    bool noReference = false;
    bool noTimers = false;
    bool saveOutputs = false; ///< write every setting's linear result to --output/outputs/*.exr
    bool noHighlightSprites = false; ///< the rhombi without their bokeh sprites
    std::string replot; ///< accuracy.json of an earlier run: draw its Pareto plot only
    double bladeRotationDeg = 0.0; ///< the GPU methods' hexagon; 0 = a corner on top, as the truth
    std::string scene = "blender"; ///< or "synthetic[:NAME]": input and truth rendered (docs/synthetic.md)
};

/// The scene and truth measured against, for the plot's title (set by --scene).
std::string gTruthTitle = "Blender spheres 640x480 vs Cycles thin-lens truth";

/// Figures quoted from ../shared/data/README.md for comparison: not measured here.
struct Quoted {
    const char* what;
    const char* psnr;
    const char* time;
};
constexpr Quoted kQuoted[] = {
    {"Blender compositor Defocus node, best calibrated setting", "32.9 dB", "~1.4 s per frame"},
    {"GEGL lens-blur driven by a thin-lens CoC mask", "30.4-32.6 dB", "-"},
    {"Cycles itself at 128 samples (noise only)", "37.3 dB", "-"},
    {"unblurred input", "16.5 dB", "-"},
};

/// One measured (method, settings).
struct Row {
    const MethodInfo* info = nullptr;
    MethodSettings settings;
    std::string label; ///< describe()
    std::string shortLabel;
    ErrorReport error;
    std::vector<double> wallMs;
    std::map<std::string, std::vector<double>> gpuMs; ///< per pass, in first-seen order below
    std::vector<std::string> passOrder;
    std::vector<double> gpuSumMs;
    bool pareto = false;
    cv::Mat output; ///< kept for the contact sheet (linear)
};

double loadAverage()
{
    std::ifstream file("/proc/loadavg");
    double load = std::nan("");
    file >> load;
    return load;
}

std::string shortLabel(const MethodInfo& info, const MethodSettings& s)
{
    std::string base;
    if (info.name == "mcintosh")
        base = fmt::format("M{}", s.samples);
    else if (info.name == "mcintosh-near")
        base = fmt::format("MN{}", s.samples);
    else if (info.name == "rhombi")
        base = fmt::format("H{}", s.samples);
    else if (info.name == "rhombi-near")
        base = fmt::format("HN{}", s.samples);
    else if (info.name == "riguer")
        base = "R12";
    else if (info.name == "lazy8")
        base = "L8";
    else if (info.name == "gaussian5x5")
        base = "G25";
    else
        return info.name == "reference" ? "ref" : "ref-pointy";
    if (s.resolution == Resolution::Half)
        base += "/2";
    if (s.precision == TargetFormat::Rgba32F)
        base += " 32F";
    return base;
}

/// Every (method, settings) the sweep runs, in table order.
std::vector<std::pair<const MethodInfo*, MethodSettings>> sweep(const Options& options)
{
    std::vector<std::pair<const MethodInfo*, MethodSettings>> list;
    for (const MethodInfo& info : methodRegistry()) {
        if (!options.methods.empty() &&
            std::find(options.methods.begin(), options.methods.end(), info.name) == options.methods.end())
            continue;
        if (!info.gpu) {
            if (!options.noReference)
                list.push_back({&info, MethodSettings{0, Resolution::Full, TargetFormat::Rgba32F}});
            continue;
        }
        for (const Resolution resolution : {Resolution::Full, Resolution::Half})
            for (const TargetFormat precision : {TargetFormat::Rgba16F, TargetFormat::Rgba32F})
                for (const int samples : info.samples)
                    list.push_back({&info, MethodSettings{samples, resolution, precision, !options.noHighlightSprites}});
    }
    return list;
}

/// Marks the Pareto front: no other row is both faster (median wall) and more accurate (linear PSNR).
void markPareto(std::vector<Row>& rows)
{
    std::vector<Row*> sorted;
    for (Row& row : rows)
        sorted.push_back(&row);
    std::sort(sorted.begin(), sorted.end(), [](const Row* a, const Row* b) {
        const double ma = median(a->wallMs), mb = median(b->wallMs);
        return ma != mb ? ma < mb : a->error.psnrLinear > b->error.psnrLinear;
    });
    // A point joins the front only if it beats every faster point by more than 0.01 dB: the
    // 16F and 32F runs of a setting often differ by less, which is no accuracy worth the time.
    constexpr double kToleranceDb = 0.01;
    double best = -std::numeric_limits<double>::infinity();
    for (Row* row : sorted) {
        if (row->error.psnrLinear > best + kToleranceDb) {
            row->pareto = true;
            best = row->error.psnrLinear;
        }
    }
}

std::string number(double value, int decimals)
{
    if (std::isnan(value))
        return "n/a";
    if (std::isinf(value))
        return "inf";
    return fmt::format("{:.{}f}", value, decimals);
}

Json jsonNumber(double value)
{
    return std::isfinite(value) ? Json(value) : Json(nullptr);
}

// ---- the Pareto plot ----------------------------------------------------------------------------

cv::Scalar methodColour(std::string_view name)
{
    if (name == "mcintosh")
        return {200, 110, 30}; // BGR
    if (name == "mcintosh-near")
        return {230, 170, 110};
    if (name == "rhombi")
        return {20, 170, 230};
    if (name == "rhombi-near")
        return {0, 90, 200};
    if (name == "riguer")
        return {40, 150, 40};
    if (name == "lazy8")
        return {30, 120, 220};
    if (name == "gaussian5x5")
        return {160, 60, 160};
    return {40, 40, 200};
}

cv::Mat paretoPlot(const std::vector<Row>& rows, double unblurredDb)
{
    const int width = 1100, height = 700;
    const int left = 70, right = 20, top = 50, bottom = 60;
    cv::Mat plot(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
    const cv::Rect area(left, top, width - left - right, height - top - bottom);

    double msLo = std::numeric_limits<double>::max(), msHi = 0.0, dbLo = 1e9, dbHi = -1e9;
    for (const Row& row : rows) {
        msLo = std::min(msLo, median(row.wallMs));
        msHi = std::max(msHi, median(row.wallMs));
        dbLo = std::min(dbLo, row.error.psnrLinear);
        dbHi = std::max(dbHi, row.error.psnrLinear);
    }
    msHi = std::max(msHi, 1400.0); // the quoted Blender point
    dbHi = std::max(dbHi, 35.0);   // the 'high' target line
    // Decades from below the fastest point; at least 0.15 decades of room after the slowest.
    const double x0 = std::floor(std::log10(msLo));
    const double x1 = std::max(std::ceil(std::log10(msHi)), std::log10(msHi) + 0.15);
    const double y0 = std::floor(dbLo) - 0.5, y1 = std::ceil(dbHi) + 0.5;
    const auto px = [&](double ms) {
        return area.x + static_cast<int>(std::lround((std::log10(ms) - x0) / (x1 - x0) * area.width));
    };
    const auto py = [&](double db) {
        return area.y + area.height - static_cast<int>(std::lround((db - y0) / (y1 - y0) * area.height));
    };
    const cv::Scalar grid(225, 225, 225), ink(40, 40, 40);
    const int font = cv::FONT_HERSHEY_SIMPLEX;

    for (double decade = x0; decade <= x1; ++decade)
        for (const double m : {1.0, 2.0, 5.0}) {
            const double ms = m * std::pow(10.0, decade);
            if (std::log10(ms) > x1 + 1e-9)
                continue;
            const int x = px(ms);
            cv::line(plot, {x, area.y}, {x, area.y + area.height}, grid, 1);
            int baseline = 0;
            const cv::Size text = cv::getTextSize(number(ms, 0), font, 0.45, 1, &baseline);
            const cv::Point at(std::min(x - text.width / 2, width - text.width - 2), area.y + area.height + 18);
            cv::putText(plot, number(ms, 0), at, font, 0.45, ink, 1, cv::LINE_AA);
        }
    for (double db = std::ceil(y0); db <= y1; db += 1.0) {
        const int y = py(db);
        cv::line(plot, {area.x, y}, {area.x + area.width, y}, grid, 1);
        cv::putText(plot, number(db, 0), {area.x - 30, y + 5}, font, 0.45, ink, 1, cv::LINE_AA);
    }
    cv::rectangle(plot, area, ink, 1);
    cv::putText(plot, "ms per frame (wall, median; log scale)", {area.x + area.width / 2 - 150, height - 15}, font, 0.5,
                ink, 1, cv::LINE_AA);
    cv::putText(plot, "dB", {15, area.y + 10}, font, 0.5, ink, 1, cv::LINE_AA);
    cv::putText(plot,
                fmt::format("{}: linear PSNR (clipped to [0,1]); unblurred {:.1f} dB", gTruthTitle, unblurredDb),
                {left, 30}, font, 0.55, ink, 1, cv::LINE_AA);

    // The accuracy targets and the quoted Blender point.
    const auto dashedH = [&](double db, const std::string& text) {
        const int y = py(db);
        for (int x = area.x; x < area.x + area.width; x += 12)
            cv::line(plot, {x, y}, {std::min(x + 6, area.x + area.width), y}, cv::Scalar(120, 120, 120), 1);
        cv::putText(plot, text, {area.x + 5, y - 4}, font, 0.4, cv::Scalar(100, 100, 100), 1, cv::LINE_AA);
    };
    dashedH(33.0, "33 dB: balanced target");
    dashedH(35.0, "35 dB: high target");
    {
        const int x = px(60.0);
        for (int y = area.y; y < area.y + area.height; y += 12)
            cv::line(plot, {x, y}, {x, std::min(y + 6, area.y + area.height)}, cv::Scalar(120, 120, 120), 1);
        cv::putText(plot, "60 ms", {x + 3, area.y + 14}, font, 0.4, cv::Scalar(100, 100, 100), 1, cv::LINE_AA);
        const cv::Point blender(px(1400.0), py(32.9));
        cv::drawMarker(plot, blender, cv::Scalar(0, 0, 0), cv::MARKER_DIAMOND, 12, 1, cv::LINE_AA);
        cv::putText(plot, "Blender Defocus (quoted, not measured)", blender + cv::Point(-120, 20), font, 0.38,
                    cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    }

    // The front, connected.
    std::vector<const Row*> front;
    for (const Row& row : rows)
        if (row.pareto)
            front.push_back(&row);
    std::sort(front.begin(), front.end(),
              [](const Row* a, const Row* b) { return median(a->wallMs) < median(b->wallMs); });
    for (std::size_t i = 1; i < front.size(); ++i)
        cv::line(plot, {px(median(front[i - 1]->wallMs)), py(front[i - 1]->error.psnrLinear)},
                 {px(median(front[i]->wallMs)), py(front[i]->error.psnrLinear)}, cv::Scalar(0, 0, 230), 2,
                 cv::LINE_AA);

    // Points, then labels placed where they overlap no point and no earlier label: the nearest free
    // spot on rings around the point, with a thin leader line when it had to go further out.
    std::vector<cv::Rect> taken;
    for (const Row& row : rows) {
        const cv::Point p(px(median(row.wallMs)), py(row.error.psnrLinear));
        const cv::Scalar colour = methodColour(row.info->name);
        const bool full = row.settings.resolution == Resolution::Full;
        if (row.settings.precision == TargetFormat::Rgba32F)
            cv::rectangle(plot, p - cv::Point(4, 4), p + cv::Point(4, 4), colour, full ? cv::FILLED : 1, cv::LINE_AA);
        else
            cv::circle(plot, p, 4, colour, full ? cv::FILLED : 1, cv::LINE_AA);
        const int r = row.pareto ? 9 : 5;
        if (row.pareto)
            cv::circle(plot, p, 8, cv::Scalar(0, 0, 230), 2, cv::LINE_AA);
        taken.push_back(cv::Rect(p - cv::Point(r, r), cv::Size(2 * r + 1, 2 * r + 1)));
    }
    for (const Row& row : rows) {
        const cv::Point p(px(median(row.wallMs)), py(row.error.psnrLinear));
        int baseline = 0;
        const double scale = 0.33;
        const cv::Size text = cv::getTextSize(row.shortLabel, font, scale, 1, &baseline);
        cv::Rect chosen;
        bool far = false;
        for (const int ring : {10, 18, 28, 40, 54}) {
            for (int k = 0; k < 8 && chosen.empty(); ++k) {
                // Right, left, up, down first, then the diagonals.
                static constexpr int kDirections[8][2] = {{1, 0}, {-1, 0}, {0, -1}, {0, 1},
                                                          {1, -1}, {-1, -1}, {1, 1}, {-1, 1}};
                const int dx = kDirections[k][0], dy = kDirections[k][1];
                const int x = dx > 0 ? p.x + ring : dx < 0 ? p.x - ring - text.width : p.x - text.width / 2;
                const int y = dy > 0 ? p.y + ring : dy < 0 ? p.y - ring - text.height : p.y - text.height / 2;
                const cv::Rect box(x, y, text.width, text.height + baseline);
                const bool inside = (box & area) == box;
                const bool free = std::none_of(taken.begin(), taken.end(),
                                               [&](const cv::Rect& t) { return (t & box).area() > 0; });
                if (inside && free) {
                    chosen = box;
                    far = ring > 18;
                }
            }
            if (!chosen.empty())
                break;
        }
        if (chosen.empty())
            chosen = cv::Rect(p.x + 10, p.y - text.height / 2, text.width, text.height + baseline);
        taken.push_back(chosen);
        const cv::Scalar ink2 = row.pareto ? cv::Scalar(0, 0, 180) : cv::Scalar(70, 70, 70);
        if (far) {
            const cv::Point anchor(std::clamp(p.x, chosen.x, chosen.x + chosen.width),
                                   std::clamp(p.y, chosen.y, chosen.y + chosen.height));
            cv::line(plot, p, anchor, cv::Scalar(190, 190, 190), 1, cv::LINE_AA);
        }
        cv::putText(plot, row.shortLabel, {chosen.x, chosen.y + text.height}, font, scale, ink2, 1, cv::LINE_AA);
    }

    // Legend.
    int ly = area.y + area.height - 186;
    const int lx = area.x + area.width - 330;
    const cv::Rect legend(cv::Point(lx - 8, ly - 16), cv::Point(area.x + area.width - 4, area.y + area.height - 4));
    cv::rectangle(plot, legend, cv::Scalar(250, 250, 250), cv::FILLED);
    cv::rectangle(plot, legend, grid, 1);
    for (const auto& [name, text] :
         std::vector<std::pair<std::string, std::string>>{{"mcintosh", "M<n>: McIntosh, n taps per pass"},
                                                          {"mcintosh-near", "MN<n>: McIntosh + near layer"},
                                                          {"rhombi", "H<n>: rhombi sum, n taps per line"},
                                                          {"rhombi-near", "HN<n>: rhombi + scatter as gather"},
                                                          {"riguer", "R12: Riguer 12-tap Poisson"},
                                                          {"lazy8", "L8: lazy 8-point"},
                                                          {"gaussian5x5", "G25: 5x5 Gaussian"},
                                                          {"reference", "ref: CPU scatter reference"}}) {
        cv::circle(plot, {lx, ly - 4}, 4, methodColour(name), cv::FILLED, cv::LINE_AA);
        cv::putText(plot, text, {lx + 10, ly}, font, 0.4, ink, 1, cv::LINE_AA);
        ly += 17;
    }
    cv::putText(plot, "filled: full res, hollow: /2 = half res; circle 16F, square 32F", {lx - 2, ly}, font, 0.36, ink,
                1, cv::LINE_AA);
    ly += 16;
    cv::circle(plot, {lx, ly - 4}, 7, cv::Scalar(0, 0, 230), 2, cv::LINE_AA);
    cv::putText(plot, "Pareto front (connected)", {lx + 12, ly}, font, 0.4, ink, 1, cv::LINE_AA);
    return plot;
}

// ---- the contact sheet --------------------------------------------------------------------------

/// Where the crops go: the two brightest highlights of the input, the strongest edge between an
/// in-focus object and a blurred one, and the strongest edge of a blurred foreground.
std::vector<std::pair<std::string, cv::Rect>> cropWindows(const cv::Mat& linear, const cv::Mat& coc, int size)
{
    const cv::Rect image(0, 0, linear.cols, linear.rows);
    const auto window = [&](cv::Point centre) {
        cv::Rect r(centre.x - size / 2, centre.y - size / 2, size, size);
        r.x = std::clamp(r.x, 0, image.width - size);
        r.y = std::clamp(r.y, 0, image.height - size);
        return r;
    };
    std::vector<std::pair<std::string, cv::Rect>> windows;

    cv::Mat edgeFocus = cv::Mat::zeros(coc.size(), CV_32F), edgeNear = cv::Mat::zeros(coc.size(), CV_32F);
    for (int y = 0; y + 1 < coc.rows; ++y)
        for (int x = 0; x + 1 < coc.cols; ++x)
            for (const cv::Point d : {cv::Point(1, 0), cv::Point(0, 1)}) {
                const float a = coc.at<float>(y, x), b = coc.at<float>(y + d.y, x + d.x);
                const float jump = std::abs(a - b);
                if (jump <= 1.0f)
                    continue;
                if (std::min(std::abs(a), std::abs(b)) < 1.0f)
                    edgeFocus.at<float>(y, x) += jump;
                if (std::min(a, b) < -10.0f)
                    edgeNear.at<float>(y, x) += jump;
            }
    for (auto [name, map] : {std::pair<std::string, cv::Mat>{"focus edge", edgeFocus},
                             std::pair<std::string, cv::Mat>{"near edge", edgeNear}}) {
        cv::Mat summed;
        cv::boxFilter(map, summed, CV_32F, {size / 2, size / 2}, {-1, -1}, false);
        cv::Point at;
        cv::minMaxLoc(summed, nullptr, nullptr, nullptr, &at);
        windows.emplace_back(name, window(at));
    }

    cv::Mat luminance;
    cv::cvtColor(linear, luminance, cv::COLOR_BGR2GRAY);
    for (int i = 0; i < 2; ++i) {
        cv::Point at;
        cv::minMaxLoc(luminance, nullptr, nullptr, nullptr, &at);
        windows.emplace_back(fmt::format("highlight{}", i + 1), window(at));
        cv::circle(luminance, at, size, cv::Scalar(0), cv::FILLED); // the next one lies elsewhere
    }
    return windows;
}

cv::Mat contactSheetOf(const std::vector<std::pair<std::string, const cv::Mat*>>& images,
                       const std::vector<std::pair<std::string, cv::Rect>>& windows, int zoom)
{
    std::vector<std::pair<std::string, cv::Mat>> tiles;
    for (const auto& [kind, rect] : windows) {
        for (std::size_t i = 0; i < images.size(); ++i) {
            cv::Mat tile;
            cv::resize(encodeSrgb((*images[i].second)(rect).clone()), tile, {}, zoom, zoom, cv::INTER_NEAREST);
            const std::string label = i == 0 ? fmt::format("input: {}", kind) : images[i].first;
            tiles.emplace_back(label, tile);
        }
    }
    return contactSheet(tiles, static_cast<int>(images.size()));
}

// ---- output -------------------------------------------------------------------------------------

void printTable(const std::vector<Row>& rows, const ErrorReport& unblurred)
{
    fmt::print("\n{:<28}{:>8}{:>8}{:>8}{:>9}{:>9}{:>9}{:>10}{:>10}  {}\n", "method (samples scale prec.)", "lin dB",
               "sRGB dB", "SSIM", "focus dB", "blur dB", "edge dB", "wall ms", "GPU ms", "Pareto");
    const auto line = [](const std::string& label, const ErrorReport& e, double wall, double gpu, bool pareto) {
        fmt::print("{:<28}{:>8}{:>8}{:>8}{:>9}{:>9}{:>9}{:>10}{:>10}  {}\n", label, number(e.psnrLinear, 2),
                   number(e.psnrSrgb, 2), number(e.ssim, 4), number(e.regionPsnr[0], 2), number(e.regionPsnr[1], 2),
                   number(e.regionPsnr[2], 2), number(wall, 1), number(gpu, 1), pareto ? "*" : "");
    };
    line("input (unblurred)", unblurred, 0.0, std::nan(""), false);
    for (const Row& row : rows)
        line(row.label, row.error, median(row.wallMs), median(row.gpuSumMs), row.pareto);
}

void writeCsv(const fs::path& file, const std::vector<Row>& rows)
{
    std::ofstream out(file);
    out << "method,samples,resolution,precision,psnr_linear_db,psnr_srgb_db,ssim,psnr_in_focus_db,"
           "psnr_out_of_focus_db,psnr_depth_edge_db,wall_ms_median,gpu_ms_median,runs,pareto,gpu_passes\n";
    for (const Row& row : rows) {
        std::string passes;
        for (const std::string& name : row.passOrder)
            passes += fmt::format("{}{}={}", passes.empty() ? "" : ";", name, number(median(row.gpuMs.at(name)), 3));
        out << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", row.info->name, row.settings.samples,
                           resolutionName(row.settings.resolution), precisionName(row.settings.precision),
                           number(row.error.psnrLinear, 3), number(row.error.psnrSrgb, 3), number(row.error.ssim, 5),
                           number(row.error.regionPsnr[0], 3), number(row.error.regionPsnr[1], 3),
                           number(row.error.regionPsnr[2], 3), number(median(row.wallMs), 2),
                           number(median(row.gpuSumMs), 2), row.wallMs.size(), row.pareto ? 1 : 0, passes);
    }
    if (!out)
        throw std::runtime_error(fmt::format("cannot write {}", file.string()));
}

Json errorJson(const ErrorReport& e)
{
    Json regions = Json::object();
    for (const Region region : kRegions) {
        const auto i = static_cast<std::size_t>(region);
        regions[std::string(regionName(region))] = {{"psnrLinearDb", jsonNumber(e.regionPsnr[i])},
                                                    {"share", e.regionShare[i]}};
    }
    return {{"psnrLinearDb", jsonNumber(e.psnrLinear)},
            {"psnrSrgbDb", jsonNumber(e.psnrSrgb)},
            {"ssim", jsonNumber(e.ssim)},
            {"regions", regions}};
}

/// Redraws the Pareto plot of an earlier run from its accuracy.json (for documentation, after a
/// change to the plot itself), without measuring anything.
int replot(const Options& options)
{
    std::ifstream file(options.replot);
    if (!file)
        throw std::runtime_error(fmt::format("cannot read {}", options.replot));
    const Json json = Json::parse(file);
    std::vector<Row> rows;
    for (const Json& result : json.at("results")) {
        Row row;
        row.info = findMethod(result.at("method").get<std::string>());
        if (!row.info)
            throw std::runtime_error(fmt::format("{}: unknown method {}", options.replot, result.at("method").dump()));
        row.settings.samples = result.at("samples").get<int>();
        row.settings.resolution = result.at("resolution") == "half" ? Resolution::Half : Resolution::Full;
        row.settings.precision = result.at("precision") == "32F"    ? TargetFormat::Rgba32F
                                 : result.at("precision") == "auto" ? TargetFormat::Auto
                                                                    : TargetFormat::Rgba16F;
        row.shortLabel = shortLabel(*row.info, row.settings);
        row.error.psnrLinear = result.at("error").at("psnrLinearDb").get<double>();
        row.wallMs = {result.at("wallMsMedian").get<double>()};
        row.pareto = result.at("pareto").get<bool>();
        rows.push_back(std::move(row));
    }
    fs::create_directories(options.out);
    const double unblurred = json.at("unblurred").at("psnrLinearDb").get<double>();
    if (!cv::imwrite((fs::path(options.out) / "pareto.png").string(), paretoPlot(rows, unblurred),
                     {cv::IMWRITE_PNG_COMPRESSION, 9}))
        throw std::runtime_error("cannot write pareto.png");
    fmt::print("wrote {}/pareto.png from {}\n", options.out, options.replot);
    return kExitDone;
}

int run(const Options& options, const std::string& commandLine)
{
    if (!options.replot.empty())
        return replot(options);
    LensSettings lens = blenderSpheresLens();
    lens.bladeRotationDeg = options.bladeRotationDeg;
    cv::Mat color, depth, truth;
    std::string sceneLabel = options.data;
    // --scene synthetic[:NAME]: input and truth rendered here with the Blender scene's lens and
    // aperture (6 blades, a corner up), the truth from 256 lens positions; GL is needed first.
    std::optional<gl::EglContext> early;
    if (options.scene != "blender") {
        early.emplace(gl::EglContext::create());
        const std::string name = options.scene.size() > 10 ? options.scene.substr(10) : "spheres";
        SyntheticSettings settings;
        settings.frames = 1;
        settings.lens = blenderSpheresLens(); // the truth's aperture has a corner up, as Cycles' does
        settings.focusPull = false;
        SyntheticScene scene(syntheticScene(name), settings);
        const SyntheticImages images = scene.render(0);
        color = images.frame.color;
        depth = images.frame.depth;
        truth = images.reference;
        sceneLabel = "synthetic:" + name;
        gTruthTitle = fmt::format("synthetic {} 640x480 vs {}-sample accumulated thin-lens truth", name,
                                  settings.aperture.samples);
        fmt::print(stderr, "defocus-bench-accuracy: {} rendered, truth {} renders in {:.0f} ms\n", sceneLabel,
                   settings.aperture.samples, images.referenceMs);
    } else {
        const fs::path dir = options.data;
        std::error_code ec;
        if (!fs::is_directory(dir, ec))
            throw std::runtime_error(fmt::format(
                "data folder '{}' not found (looked from '{}'); run from the repository root or pass --data DIR",
                dir.string(), fs::current_path(ec).string()));
        color = readColor(dir / "color_linear.exr");
        depth = readDepth(dir / "depth.exr", 1000.0);
        truth = readColor(dir / "truth_f1.4_focus5_linear.exr");
        if (truth.size() != color.size())
            throw std::runtime_error("the truth and the input differ in size");
    }
    const Frame frame{color, depth, 0.0, 0, sceneLabel};

    // Regions from the thin-lens CoC of the filled depth, as the filter sees it.
    const cv::Mat coc = cocMap(prepareDepth(depth, color.size(), static_cast<float>(lens.focusM)).metres,
                               cocCoefficients(lens, color.cols));
    const cv::Mat regions = regionMap(coc);
    const ErrorReport unblurred = measureError(color, truth, regions);

    auto context = early ? std::move(*early) : gl::EglContext::create();
    const gl::ContextInfo& info = context.info();
    const std::string cpu = cpuModel();
    const unsigned cores = std::thread::hardware_concurrency();
    const double loadBefore = loadAverage();
    fmt::print("defocus-bench-accuracy, {}\n", utcNow());
    fmt::print("GL renderer: {}; GL {}; EGL platform: {}\nCPU: {}, {} cores; load average {:.2f} before the runs\n",
               info.glRenderer, info.glVersion, info.platform, cpu, cores, loadBefore);
    fmt::print("scene: {} {}x{}; lens {} mm f/{} focused at {} m, {} mm sensor, field of view from the {}, "
               "max-coc {} px\n",
               sceneLabel, color.cols, color.rows, lens.focalLengthMm, lens.fNumber, lens.focusM, lens.sensorWidthMm,
               lens.fieldOfView == FieldOfView::FocalLength ? "focal length" : "image distance", lens.maxCocPx);
    fmt::print("measure: {}; PSNR of linear values clipped to [0,1] (and after sRGB "
               "encoding), SSIM on luma; regions in-focus {:.1f}%, out-of-focus {:.1f}%, depth-edge {:.1f}% "
               "(bench/Metrics.hpp)\n",
               gTruthTitle, 100 * unblurred.regionShare[0], 100 * unblurred.regionShare[1], 100 * unblurred.regionShare[2]);
    fmt::print("time: median of {} runs after {} warm-up runs per setting (the CPU references: 1 run); wall = the "
               "whole frame incl. depth prep, scaling, upload and readback; GPU = GL_TIME_ELAPSED per pass{}\n",
               options.runs, options.warmup,
               options.noTimers ? " (off)" : info.timerQueries ? "" : " (not offered by this driver)");
    fmt::print("command: {}\n", commandLine);

    // One method instance per (method, resolution, precision), so that no run reallocates
    // targets; the GPU settings run round-robin (every setting once per round), so that load from
    // elsewhere on a shared machine spreads over all of them instead of skewing a few.
    std::map<std::string, std::unique_ptr<Method>> instances;
    const auto instance = [&](const MethodInfo& methodInfo, const MethodSettings& settings) -> Method& {
        const std::string key = fmt::format("{} {} {}", methodInfo.name, resolutionName(settings.resolution),
                                            precisionName(settings.precision));
        auto& method = instances[key];
        if (!method)
            method = createMethod(methodInfo.name, !options.noTimers);
        return *method;
    };
    std::vector<Row> rows;
    for (const auto& [methodInfo, settings] : sweep(options)) {
        Row row;
        row.info = methodInfo;
        row.settings = settings;
        row.label = describe(*methodInfo, settings);
        row.shortLabel = shortLabel(*methodInfo, settings);
        rows.push_back(std::move(row));
    }
    const auto measureOnce = [&](Row& row, bool keep) {
        MethodResult result = instance(*row.info, row.settings).run(frame, lens, row.settings);
        if (!keep)
            return;
        row.wallMs.push_back(result.wallMs);
        double sum = 0.0;
        for (const PassTime& pass : result.gpu) {
            if (!row.gpuMs.count(pass.name))
                row.passOrder.push_back(pass.name);
            row.gpuMs[pass.name].push_back(pass.ms);
            sum += pass.ms;
        }
        if (!result.gpu.empty())
            row.gpuSumMs.push_back(sum);
        row.output = result.linear;
    };
    fmt::print(stderr, "defocus-bench-accuracy: {} GPU warm-up round(s), {} measured rounds of {} settings\n",
               options.warmup, options.runs,
               std::count_if(rows.begin(), rows.end(), [](const Row& r) { return r.info->gpu; }));
    for (int round = 0; round < options.warmup + options.runs; ++round) {
        fmt::print(stderr, "defocus-bench-accuracy: round {}/{}\n", round + 1, options.warmup + options.runs);
        for (Row& row : rows)
            if (row.info->gpu)
                measureOnce(row, round >= options.warmup);
    }
    for (Row& row : rows) {
        if (!row.info->gpu) {
            fmt::print(stderr, "defocus-bench-accuracy: {} (one run)\n", row.label);
            measureOnce(row, true);
        }
        row.error = measureError(row.output, truth, regions);
    }
    markPareto(rows);
    printTable(rows, unblurred);

    fmt::print("\nQuoted for comparison from ../shared/data/README.md -- NOT measured in this run:\n");
    for (const Quoted& q : kQuoted)
        fmt::print("  {:<58}{:>14}   {}\n", q.what, q.psnr, q.time);
    fmt::print("  (this run measured the unblurred input at {:.2f} dB)\n", unblurred.psnrLinear);

    fmt::print("\nPresets (bench/methods/Presets.cpp):\n");
    for (const Preset& p : presets()) {
        const auto match = std::find_if(rows.begin(), rows.end(), [&](const Row& row) {
            return row.info->name == p.method && row.settings.samples == p.settings.samples &&
                   row.settings.resolution == p.settings.resolution && row.settings.precision == p.settings.precision;
        });
        fmt::print("  {:<9} {:<26} recorded {:.2f} dB {:.1f} ms; this run {} dB {} ms\n", p.name,
                   describe(*findMethod(p.method), p.settings), p.psnrDb, p.msPerFrame,
                   match == rows.end() ? "n/a" : number(match->error.psnrLinear, 2),
                   match == rows.end() ? "n/a" : number(median(match->wallMs), 1));
    }

    // Files.
    const fs::path out = options.out;
    fs::create_directories(out);
    writeCsv(out / "accuracy.csv", rows);

    Json json;
    json["tool"] = "defocus-bench-accuracy";
    json["date"] = utcNow();
    json["command"] = commandLine;
    json["machine"] = {{"cpu", cpu},
                       {"cores", cores},
                       {"loadAverageBefore", jsonNumber(loadBefore)},
                       {"glRenderer", info.glRenderer},
                       {"glVersion", info.glVersion},
                       {"eglPlatform", info.platform},
                       {"timerQueries", info.timerQueries && !options.noTimers}};
    json["scene"] = {{"data", sceneLabel},
                     {"width", color.cols},
                     {"height", color.rows},
                     {"lens", {{"focalLengthMm", lens.focalLengthMm},
                               {"fNumber", lens.fNumber},
                               {"focusM", lens.focusM},
                               {"sensorWidthMm", lens.sensorWidthMm},
                               {"fieldOfView", fieldOfViewName(lens.fieldOfView)},
                               {"maxCocPx", lens.maxCocPx}}}};
    json["timing"] = {{"runs", options.runs}, {"warmup", options.warmup}, {"statistic", "median"}};
    json["unblurred"] = errorJson(unblurred);
    Json results = Json::array();
    for (const Row& row : rows) {
        Json gpu = Json::object();
        for (const std::string& name : row.passOrder)
            gpu[name] = jsonNumber(median(row.gpuMs.at(name)));
        results.push_back({{"method", row.info->name},
                           {"label", row.label},
                           {"samples", row.settings.samples},
                           {"resolution", resolutionName(row.settings.resolution)},
                           {"precision", precisionName(row.settings.precision)},
                           {"error", errorJson(row.error)},
                           {"wallMsMedian", jsonNumber(median(row.wallMs))},
                           {"wallMsRuns", row.wallMs},
                           {"gpuMsMedian", jsonNumber(median(row.gpuSumMs))},
                           {"gpuMsPerPass", gpu},
                           {"pareto", row.pareto}});
    }
    json["results"] = results;
    Json quoted = Json::array();
    for (const Quoted& q : kQuoted)
        quoted.push_back({{"what", q.what}, {"psnr", q.psnr}, {"time", q.time}, {"measured", false}});
    json["quotedNotMeasured"] = quoted;
    {
        std::ofstream file(out / "accuracy.json");
        file << json.dump(2) << "\n";
        if (!file)
            throw std::runtime_error(fmt::format("cannot write {}", (out / "accuracy.json").string()));
    }

    if (options.saveOutputs) {
        // One EXR per setting, named like the CSV's rows ("rhombi-near 12 full 32F.exr"), for
        // error maps and crops of one's own.
        fs::create_directories(out / "outputs");
        for (const Row& row : rows) {
            const fs::path file = out / "outputs" / (row.label + ".exr");
            if (!cv::imwrite(file.string(), row.output))
                throw std::runtime_error(fmt::format("cannot write {}", file.string()));
        }
    }

    if (!cv::imwrite((out / "pareto.png").string(), paretoPlot(rows, unblurred.psnrLinear),
                     {cv::IMWRITE_PNG_COMPRESSION, 9}))
        throw std::runtime_error("cannot write pareto.png");

    // Contact sheet: input, truth, the references, the presets' rows, the older methods.
    const std::string truthLabel = options.scene == "blender" ? "truth (Cycles)" : "truth (accumulated)";
    std::vector<std::pair<std::string, const cv::Mat*>> images{{"input", &color}, {truthLabel, &truth}};
    const auto add = [&](const std::string& label, const std::string& method, const MethodSettings* settings) {
        for (const Row& row : rows)
            if (row.info->name == method &&
                (!settings || (row.settings.samples == settings->samples &&
                               row.settings.resolution == settings->resolution &&
                               row.settings.precision == settings->precision))) {
                if (std::none_of(images.begin(), images.end(), [&](const auto& i) { return i.second == &row.output; }))
                    images.emplace_back(label.empty() ? row.shortLabel : label, &row.output);
                return;
            }
    };
    add("", "reference-pointy", nullptr);
    add("", "reference", nullptr);
    for (const Preset& p : presets())
        add(fmt::format("{}: {}", p.name, shortLabel(*findMethod(p.method), p.settings)), std::string(p.method),
            &p.settings);
    for (const char* name : {"riguer", "lazy8", "gaussian5x5"}) {
        const MethodSettings full{*findMethod(name)->samples.begin(), Resolution::Full, TargetFormat::Rgba16F};
        add("", name, &full);
    }
    const auto windows = cropWindows(color, coc, 80);
    const cv::Mat sheet = contactSheetOf(images, windows, 3);
    if (!cv::imwrite((out / "contact_sheet.png").string(), sheet, {cv::IMWRITE_PNG_COMPRESSION, 9}))
        throw std::runtime_error("cannot write contact_sheet.png");
    fmt::print("\nwrote {}/accuracy.csv, accuracy.json, pareto.png, contact_sheet.png (crops:", out.string());
    for (const auto& [kind, rect] : windows)
        fmt::print(" {} at ({},{})", kind, rect.x, rect.y);
    fmt::print(", {}x{} px)\n", windows.front().second.width, windows.front().second.height);
    return kExitDone;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"defocus-bench-accuracy: error against a path-traced thin lens and time per frame, for every "
                 "depth-of-field method and setting, on the Blender spheres scene"};
    Options options;
    std::string methods;
    app.add_option("--data", options.data, "folder with color_linear.exr, depth.exr, truth_f1.4_focus5_linear.exr")
        ->capture_default_str();
    app.add_option("-o,--output", options.out, "output folder for CSV, JSON, pareto.png, contact_sheet.png")
        ->capture_default_str();
    app.add_option("--runs", options.runs, "timed runs per setting (median reported)")
        ->check(cli::between(5, 1000))
        ->capture_default_str();
    app.add_option("--warmup", options.warmup, "unmeasured runs before them")
        ->check(cli::between(0, 100))
        ->capture_default_str();
    app.add_option("--methods", methods, "comma-separated subset of: mcintosh,mcintosh-near,rhombi,rhombi-near,riguer,"
                                         "lazy8,gaussian5x5,reference,reference-pointy (default: all)");
    app.add_flag("--no-reference", options.noReference, "skip the CPU references (seconds each)");
    app.add_option("--blade-rotation", options.bladeRotationDeg,
                   "hexagon of the GPU methods, degrees (0 = a corner on top, as the truths; 30 = flat top)")
        ->check(cli::between(-180.0, 180.0))
        ->capture_default_str();
    app.add_flag("--no-timers", options.noTimers, "no GL timer queries");
    app.add_flag("--no-highlight-sprites", options.noHighlightSprites,
                 "the rhombi without bokeh sprites for lights (what they bought)");
    app.add_flag("--save-outputs", options.saveOutputs,
                 "also write every setting's result, linear float, to --output/outputs/LABEL.exr");
    app.add_option("--replot", options.replot, "only redraw --output/pareto.png from an earlier run's accuracy.json");
    std::vector<std::string> scenes{"blender", "synthetic"};
    for (const std::string& name : syntheticSceneNames())
        scenes.push_back("synthetic:" + name);
    std::vector<std::string> sceneArgs;
    CorpusOptions corpus;
    app.add_option("--scene", sceneArgs,
                   "blender (default: --data, the Cycles truth, every method and setting), synthetic[:NAME] "
                   "(spheres or edges, rendered with a 256-sample thin-lens truth; docs/synthetic.md), or "
                   "scene folders (scene.json) and corpus folders of them, repeatable: the presets on each, "
                   "per zone, with the minimum and median (docs/accuracy.md)");
    app.add_option("--anchors", corpus.anchors,
                   "scene folders only: folder of other tools' outputs, ANCHORS/SCENE/{blender-defocus,"
                   "gegl-lens-blur}.exr (scripts/corpus/anchors.py), measured beside the presets");
    std::string presetList;
    app.add_option("--presets", presetList,
                   "scene folders only: comma-separated presets to run (default: all); NAME:quarter runs "
                   "preset NAME with quarter size on large blur, NAME:half-only without (the presets' own), "
                   "NAME:no-sprites without bokeh sprites, NAME:16f and NAME:32f with half- or full-float "
                   "targets (they combine: NAME:no-sprites:quarter)");
    app.add_option("--scale", corpus.scale,
                   "scene folders only: enlarge every scene by this factor (colour and truth bilinear, depth "
                   "nearest, lens unchanged: the CoC in pixels grows with it), to judge large frames' blur")
        ->check(cli::between(1, 8))
        ->capture_default_str();
    app.add_flag("--missing-ok", corpus.missingOk,
                 "scene folders only: exit 77 (skipped) when a --scene folder does not exist");
    if (const auto status = cli::parse(app, argc, argv))
        return *status;
    cli::logToStderr("defocus-bench-accuracy");

    std::string commandLine;
    for (int i = 0; i < argc; ++i)
        commandLine += (i ? " " : "") + std::string(argv[i]);
    const auto named = [&](const std::string& s) {
        return std::find(scenes.begin(), scenes.end(), s) != scenes.end();
    };
    if (!sceneArgs.empty() && std::none_of(sceneArgs.begin(), sceneArgs.end(), named)) {
        corpus.scenes = sceneArgs;
        std::stringstream presetNames(presetList);
        for (std::string name; std::getline(presetNames, name, ',');)
            if (!name.empty())
                corpus.presets.push_back(name);
        corpus.out = options.out;
        corpus.saveOutputs = options.saveOutputs;
        try {
            return runCorpusAccuracy(corpus, commandLine);
        } catch (const std::exception& error) {
            fmt::print(stderr, "defocus-bench accuracy: error: {}\n", error.what());
            return bench::statusFor(error);
        }
    }
    if (sceneArgs.size() > 1) {
        fmt::print(stderr, "defocus-bench-accuracy: error: --scene {} runs alone; scene folders may be repeated\n",
                   *std::find_if(sceneArgs.begin(), sceneArgs.end(), named));
        return kExitUsage;
    }
    if (sceneArgs.size() == 1)
        options.scene = sceneArgs.front();

    std::stringstream list(methods);
    for (std::string name; std::getline(list, name, ',');) {
        if (name.empty())
            continue;
        if (!findMethod(name)) {
            fmt::print(stderr, "defocus-bench-accuracy: error: --methods: no method called '{}'\n", name);
            return kExitUsage;
        }
        options.methods.push_back(name);
    }
    try {
        return run(options, commandLine);
    } catch (const std::exception& error) {
        fmt::print(stderr, "defocus-bench-accuracy: error: {}\n", error.what());
        return bench::statusFor(error);
    }
}
