// SPDX-License-Identifier: LGPL-2.1-or-later
// Command-line plumbing shared by the defocus programs: parse errors, stderr logging, signals.
#include "samples/CliOptions.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "defocus/Filter.hpp"
#include "sources/FrameSource.hpp"
#include "sources/IoLog.hpp"

namespace defocus::cli {
namespace {

std::atomic<int> gSignal{0};

extern "C" void onStopSignal(int signal)
{
    int none = 0;
    gSignal.compare_exchange_strong(none, signal); // the first signal decides the status
}

/// A range check: `accepts` the number, else the message "must be DESCRIPTION, not VALUE".
CLI::Validator rangeCheck(std::function<bool(double)> accepts, std::string description, std::string name)
{
    return CLI::Validator(
        [accepts = std::move(accepts), description](std::string& text) -> std::string {
            double value = 0.0;
            if (!CLI::detail::lexical_cast(text, value))
                return {}; // the option's conversion says what is wrong
            return accepts(value) ? std::string() : fmt::format("must be {}, not {}", description, text);
        },
        std::move(name));
}

} // namespace

std::optional<int> parse(CLI::App& app, int argc, char** argv)
{
    const std::string program = argc > 0 ? std::filesystem::path(argv[0]).filename().string() : "defocus";
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        std::fputs(app.help().c_str(), stdout);
        return kExitDone;
    } catch (const CLI::CallForAllHelp&) {
        std::fputs(app.help("", CLI::AppFormatMode::All).c_str(), stdout);
        return kExitDone;
    } catch (const CLI::CallForVersion&) {
        std::fputs((app.version() + "\n").c_str(), stdout);
        return kExitDone;
    } catch (const CLI::ParseError& error) {
        // A subcommand's own --help, or an error inside it, is reported by the subcommand.
        printError(program, fmt::format("{} (see --help)", errorMessage(error)));
        return kExitUsage;
    }
    return std::nullopt;
}

std::string errorMessage(const CLI::ParseError& error)
{
    std::string text = error.what();
    const auto colon = text.find(": must be ");
    if (dynamic_cast<const CLI::ValidationError*>(&error) && colon != std::string::npos &&
        text.find(' ') > colon)
        text.erase(colon, 1);
    return text;
}

void addVersionFlag(CLI::App& app, std::string_view program)
{
    app.set_version_flag("--version", fmt::format("{} {}", program, DEFOCUS_VERSION));
}

void printError(std::string_view program, std::string_view message)
{
    std::fflush(stdout);
    fmt::print(stderr, "{}: error: {}\n", program, message);
}

CLI::Validator positive()
{
    return rangeCheck([](double v) { return v > 0.0; }, "more than 0", "POSITIVE");
}

CLI::Validator atLeast(double minimum)
{
    // The help's words as CLI11's: NONNEGATIVE for 0, POSITIVE for 1 (the whole-number options').
    const std::string help = minimum == 0.0   ? "NONNEGATIVE"
                             : minimum == 1.0 ? "POSITIVE"
                                              : fmt::format(">={:g}", minimum);
    return rangeCheck([minimum](double v) { return v >= minimum; }, fmt::format("at least {:g}", minimum), help);
}

CLI::Validator between(double low, double high)
{
    return rangeCheck([low, high](double v) { return v >= low && v <= high; },
                      fmt::format("between {:g} and {:g}", low, high), fmt::format("{:g}..{:g}", low, high));
}

void logToStderr(std::string_view program, bool quiet, bool verbose)
{
    auto logger = spdlog::stderr_color_mt(std::string(program) + "-stderr");
    spdlog::set_default_logger(logger);
    spdlog::set_pattern(fmt::format("%^{}: %l:%$ %v", program));
    spdlog::set_level(verbose ? spdlog::level::debug : quiet ? spdlog::level::warn : spdlog::level::info);
    // libdefocus' messages, and those of the sources and sinks linked into the program, the same way.
    setLogHandler(forwardLibraryLog, LogLevel::Debug);
    setIoLogHandler(forwardLibraryLog, LogLevel::Debug);
}

void forwardLibraryLog(LogLevel level, std::string_view message)
{
    constexpr spdlog::level::level_enum kLevels[] = {spdlog::level::debug, spdlog::level::info, spdlog::level::warn,
                                                     spdlog::level::err};
    spdlog::default_logger_raw()->log(kLevels[static_cast<int>(level)], "{}", message);
}

void addCameraOptions(CLI::App& app, SourceOptions& source)
{
    app.add_option_function<std::string>(
           "--size",
           [&source](const std::string& text) {
               int width = 0, height = 0;
               char x = 0;
               std::istringstream in(text);
               if (!(in >> width >> x >> height) || (x != 'x' && x != 'X') || !in.eof() || width <= 0 || height <= 0)
                   throw CLI::ValidationError("--size", "'" + text + "' is not WIDTHxHEIGHT in pixels, e.g. 1280x720");
               source.width = width;
               source.height = height;
           },
           "Camera capture size WIDTHxHEIGHT, pixels; the driver picks the nearest it has")
        ->default_str(fmt::format("{}x{}", source.width, source.height));
    app.add_option("--camera-fps", source.fps, "Camera frame rate to ask for, Hz")
        ->check(positive())
        ->capture_default_str();
    app.add_option("--pixel-format", source.pixelFormat,
                   "Camera pixel format, a V4L2 FourCC (YUYV, MJPG, NV12, RGB3, BGR3, GREY) [default: the fastest "
                   "it offers]");
}

void addLensOptions(CLI::App& app, Lens& lens, LensNames& names, FocalRange range)
{
    app.add_option("--f-number", lens.fNumber, "Aperture as an f-number N (smaller = more blur), 0.7..64")
        ->capture_default_str();
    app.add_option("--focal-length", lens.focalLengthMm, "Lens focal length, millimetres, 1..1200")->capture_default_str();
    app.add_option("--sensor-width", lens.sensorWidthMm, "Sensor width the image spans, millimetres, 1..100")
        ->capture_default_str();
    app.add_option("--fov-from", names.fov, "Where the sensor width spans the image: image-distance (a real "
                   "camera, whose view narrows as it focuses closer) or focal-length (Blender, game engines)")
        ->check(CLI::IsMember({"image-distance", "focal-length"}))
        ->capture_default_str();
    app.add_option("--max-coc", lens.maxCocPx, "Largest blur diameter, pixels, 0..512")->capture_default_str();
    app.add_option("--coc-model", names.model,
                   "thin-lens (physical) or focal-range (blur rises linearly from --focus to max at --near/--far)")
        ->check(CLI::IsMember({"thin-lens", "focal-range"}))
        ->capture_default_str();
    // The one deliberate difference between the programs: the preview's focus moves all the time
    // (autofocus, taps, keys), so its range moves with it; defocus's range is where it is put.
    const Lens defaults;
    if (range == FocalRange::Fixed) {
        app.add_option("--near", lens.nearM,
                       "focal-range model: metres where near blur reaches --max-coc, fixed (defocus-preview's "
                       "follows its focus: by default half the focus)")
            ->capture_default_str();
        app.add_option("--far", lens.farM,
                       "focal-range model: metres where far blur reaches --max-coc, fixed (defocus-preview's "
                       "follows its focus: by default 3 x the focus)")
            ->capture_default_str();
    } else {
        app.add_option("--near", names.nearM,
                       fmt::format("focal-range model: metres where near blur reaches --max-coc at the starting "
                                   "focus, then follows the focus in proportion (defocus's stays at {:g} m) "
                                   "[default: half the focus]",
                                   defaults.nearM));
        app.add_option("--far", names.farM,
                       fmt::format("focal-range model: metres where far blur reaches --max-coc at the starting "
                                   "focus, then follows the focus in proportion (defocus's stays at {:g} m) "
                                   "[default: 3 x the focus]",
                                   defaults.farM));
    }
    app.add_option("--blades", lens.blades,
                   "Aperture blades: 0 = a circular aperture, else the polygon's corners, 3 to 16 (as Blender Cycles)")
        ->capture_default_str();
    app.add_option("--blade-rotation", lens.bladeRotationDeg,
                   "Aperture rotation, degrees counter-clockwise, as Blender Cycles: at 0 an edge faces right "
                   "(the hexagon's corner is on top; 30 = flat top)")
        ->capture_default_str();
    app.add_option("--aperture-ratio", lens.apertureRatio,
                   "Anamorphic squeeze, as Blender Cycles: the aperture's width is divided by it (2 = tall ovals)")
        ->capture_default_str();
}

void finishLens(const LensNames& names, Lens& lens)
{
    // The names are checked by CLI11.
    lens.cocModel = names.model == "focal-range" ? Lens::Model::FocalRange : Lens::Model::ThinLens;
    lens.fovFrom = names.fov == "focal-length" ? Lens::FovFrom::FocalLength : Lens::FovFrom::ImageDistance;
}

void addQualityOptions(CLI::App& app, Quality& quality, QualityNames& names)
{
    app.add_option("--quality", names.qualityPreset,
                   "Preset from the accuracy benchmark (docs/accuracy.md), all rhombi with their near field: fast (4 "
                   "taps, half size), balanced (6 taps, half size), high (12 taps, full size); --samples, "
                   "--precision, --resolution, --hexagon and --near-field override it")
        ->check(CLI::IsMember({"fast", "balanced", "high"}))
        ->capture_default_str();
    app.add_option("--samples", quality.samples, "Taps per directional blur, 2..64 [default: from --quality]");
    app.add_option("--hexagon", names.kernel,
                   "How the blurs make the hexagon: rhombi (three one-sided rhombi summed, keeps highlight energy) "
                   "or mcintosh (McIntosh et al. 2012, min of two) [default: from --quality]")
        ->check(CLI::IsMember({"rhombi", "mcintosh"}));
    app.add_option("--precision", names.precision,
                   "Intermediate render targets: 16f or 32f [default: the renderer's, 16f on a GPU, 32f on llvmpipe]")
        ->check(CLI::IsMember({"16f", "32f"}));
    app.add_option("--resolution", names.resolution,
                   "Size the blurs run at: full, or half (a quarter of the pixels; the output keeps the frame's "
                   "size and its in-focus pixels) [default: from --quality]")
        ->check(CLI::IsMember({"full", "half"}));
    app.add_flag("--near-field,!--no-near-field", names.nearField,
                 "Spread blurred foreground over what is behind it [default: from --quality]");
    app.add_flag("--highlight-sprites,!--no-highlight-sprites", quality.highlightSprites,
                 "Rhombi: lights brighter than white scatter in the aperture's shape with exact edges (bokeh sprites) "
                 "[default: on]")
        ->capture_default_str();
    app.add_option("--highlight-gain", quality.highlightGain,
                   "8-bit input: scale near-clipped pixels that get blurred up to this, so lights bloom (1 = off, 1..64)")
        ->capture_default_str();
}

void finishQuality(const CLI::App& app, QualityNames& names, Quality& q)
{
    // The names are checked by CLI11; the options given override the preset.
    q.preset = qualityNamed(names.qualityPreset).value_or(Quality::Preset::Balanced);
    if (app.count("--precision") > 0)
        q.precision = names.precision == "32f" ? Quality::Precision::F32 : Quality::Precision::F16;
    if (app.count("--hexagon") > 0)
        q.hexagon = names.kernel == "mcintosh" ? Quality::Hexagon::McIntosh : Quality::Hexagon::Rhombi;
    if (app.count("--near-field") > 0)
        q.nearField = names.nearField;
    if (app.count("--resolution") > 0)
        q.resolution = names.resolution == "half" ? Quality::Resolution::Half : Quality::Resolution::Full;
    q = resolve(q);
    names.precision = !q.precision                                ? "auto"
                      : *q.precision == Quality::Precision::F32 ? "32f"
                                                                : "16f";
    names.kernel = *q.hexagon == Quality::Hexagon::McIntosh ? "mcintosh" : "rhombi";
    names.resolution = *q.resolution == Quality::Resolution::Half ? "half" : "full";
    names.nearField = *q.nearField;
}

void addDepthScaleOption(CLI::App& app, std::optional<double>& scale)
{
    app.add_option("--depth-scale", scale,
                   "Units per metre of 16-bit depth images [default: 5000 for TUM folders, 1000 otherwise]")
        ->check(positive());
}

std::optional<int> checkSettings(const Settings& settings)
{
    Settings checked = settings;
    const auto issues = check(checked);
    for (const auto& issue : issues)
        spdlog::error("{}", issue);
    return issues.empty() ? std::nullopt : std::optional<int>(kExitUsage);
}

void catchStopSignals()
{
    std::signal(SIGINT, onStopSignal);
    std::signal(SIGTERM, onStopSignal);
}

bool stopRequested()
{
    return gSignal.load() != 0;
}

int stopSignal()
{
    return gSignal.load();
}

int stopStatus()
{
    switch (gSignal.load()) {
    case SIGINT: return kExitInterrupted;
    case SIGTERM: return kExitTerminated;
    default: return kExitDone;
    }
}

void requestStop(int signal)
{
    gSignal = signal;
}

int statusFor(const std::exception& error)
{
    if (dynamic_cast<const GlError*>(&error) || dynamic_cast<const DeviceBusy*>(&error))
        return kExitUnavailable;
    return kExitBadInput;
}

} // namespace defocus::cli
