// Command-line plumbing shared by the defocus programs: parse errors, stderr logging, signals.
#include "samples/CliOptions.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "defocus/Filter.hpp"
#include "filter/gl/EglContext.hpp"
#include "filter/gl/Program.hpp"
#include "sources/FrameSource.hpp"

namespace defocus::cli {
namespace {

std::atomic<int> gSignal{0};

extern "C" void onStopSignal(int signal)
{
    int none = 0;
    gSignal.compare_exchange_strong(none, signal); // the first signal decides the status
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
        printError(program, fmt::format("{} (see --help)", error.what()));
        return kExitUsage;
    }
    return std::nullopt;
}

void printError(std::string_view program, std::string_view message)
{
    std::fflush(stdout);
    fmt::print(stderr, "{}: error: {}\n", program, message);
}

void logToStderr(std::string_view program, bool quiet, bool verbose)
{
    auto logger = spdlog::stderr_color_mt(std::string(program) + "-stderr");
    spdlog::set_default_logger(logger);
    spdlog::set_pattern(fmt::format("%^{}: %l:%$ %v", program));
    spdlog::set_level(verbose ? spdlog::level::debug : quiet ? spdlog::level::warn : spdlog::level::info);
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
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--pixel-format", source.pixelFormat,
                   "Camera pixel format, a V4L2 FourCC (YUYV, MJPG, NV12, RGB3, BGR3, GREY) [default: the fastest "
                   "it offers]");
}

std::optional<int> checkLensAndQuality(const LensSettings& lens, const QualitySettings& quality, bool autoFocus)
{
    const auto issues = validateCommandLine(lens, quality, autoFocus);
    for (const auto& issue : issues)
        spdlog::error("{}", issue.message);
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
    if (dynamic_cast<const gl::ContextError*>(&error) || dynamic_cast<const gl::ShaderError*>(&error) ||
        dynamic_cast<const GlError*>(&error) || dynamic_cast<const DeviceBusy*>(&error))
        return kExitUnavailable;
    return kExitBadInput;
}

} // namespace defocus::cli
