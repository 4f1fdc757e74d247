// SPDX-License-Identifier: LGPL-2.1-or-later
// What every defocus program shares on its command line: parsing with one error line and exit
// status 2, logging to standard error, and Ctrl-C/SIGTERM that finish the clip in hand.
//   int main(int argc, char** argv) {
//       CLI::App app{"..."};  ...
//       if (const auto status = cli::parse(app, argc, argv)) return *status;
//       cli::logToStderr("defocus", quiet, verbose);
//       cli::catchStopSignals();
//       while (!cli::stopRequested()) { ... }
//       return cli::stopRequested() ? cli::stopStatus() : kExitDone;
//   }
#pragma once

#include <exception>
#include <optional>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "defocus/Log.hpp"
#include "defocus/Settings.hpp"
#include "samples/ExitStatus.hpp"
#include "sources/FrameSource.hpp"

namespace defocus::cli {

/// Parses the command line. --help and --version print to standard output and give 0; any
/// parse error (unknown option, bad value, value out of range, missing argument) prints one line
/// "PROGRAM: error: MESSAGE (see --help)" to standard error and gives kExitUsage. nullopt: go on.
std::optional<int> parse(CLI::App& app, int argc, char** argv);

/// --version, which prints "PROGRAM VERSION": the project's version, CMake's PROJECT_VERSION.
void addVersionFlag(CLI::App& app, std::string_view program);

/// Sends every log line (spdlog's default logger; libdefocus' and the sources' and sinks' through
/// forwardLibraryLog) to
/// standard error as "PROGRAM: LEVEL: ..."; standard output keeps only results. quiet: warnings
/// and errors only; verbose: debug too.
void logToStderr(std::string_view program, bool quiet = false, bool verbose = false);

/// A parse error's message; a failed range check (positive, atLeast, between) as a sentence,
/// "--frames must be at least 1, not 0" where CLI11 writes "--frames: must be ...".
std::string errorMessage(const CLI::ParseError& error);

/// A defocus::LogHandler that logs the library's message through spdlog's default logger, as the
/// program's own: defocus::setLogHandler(forwardLibraryLog, LogLevel::Debug) for libdefocus.
void forwardLibraryLog(LogLevel level, std::string_view message);

/// One line on standard error, "PROGRAM: error: MESSAGE", for use before logToStderr.
void printError(std::string_view program, std::string_view message);

/// Range checks for add_option(...)->check(...) whose error says the range as a user would write
/// it, "--frames must be at least 1, not 0" (CLI11's own Range prints both ends with six decimals,
/// the open one as 309 digits). Numbers are compared as doubles; text that is not a number is left
/// to the option's own conversion error.
CLI::Validator positive();                        ///< more than 0
CLI::Validator atLeast(double minimum);           ///< minimum or more (1: whole numbers, "POSITIVE")
CLI::Validator between(double low, double high);  ///< low to high, both included

/// The camera options, the same wherever a camera can be opened: --size WxH, --camera-fps and
/// --pixel-format, into `source` (its width, height, fps and pixelFormat).
void addCameraOptions(CLI::App& app, SourceOptions& source);

/// What the lens options hold besides the public Lens they fill (addLensOptions): the names
/// finishLens turns into its enums, and the preview's focal range. --focus is each program's own:
/// defocus takes auto, track and focus keys, the preview an autofocus that runs all the time.
struct LensNames {
    std::string model = "thin-lens";    ///< --coc-model
    std::string fov = "image-distance"; ///< --fov-from
    std::optional<double> nearM;        ///< --near of FocalRange::FollowsFocus (the preview)
    std::optional<double> farM;         ///< --far of FocalRange::FollowsFocus (the preview)
};

/// How a program uses --near and --far. The help of both says which the other does.
enum class FocalRange {
    Fixed,        ///< defocus: metres, 1 and 6 by default, whatever the focus does
    FollowsFocus, ///< defocus-preview: metres at the starting focus, then in proportion to it
};

/// --f-number, --focal-length, --sensor-width, --fov-from, --max-coc, --coc-model, --near, --far
/// and --blade-rotation into `lens` and `names`, with one name, default and help text in every
/// program (the public API's words: include/defocus/Settings.hpp).
void addLensOptions(CLI::App& app, Lens& lens, LensNames& names, FocalRange range);
/// After parsing: --coc-model and --fov-from into `lens`.
void finishLens(const LensNames& names, Lens& lens);

/// What the quality options hold besides the public Quality they fill (addQualityOptions): the
/// names as given, and as resolved by finishQuality (a report's words).
struct QualityNames {
    std::string qualityPreset = "balanced"; ///< --quality
    bool nearField = false;                  ///< --near-field / --no-near-field, when given
    std::string kernel;                      ///< --hexagon
    std::string precision;                   ///< --precision
    std::string resolution;                  ///< --resolution
};

/// --quality, --samples, --hexagon, --precision, --resolution, --near-field/--no-near-field,
/// --highlight-sprites/--no-highlight-sprites and --highlight-gain into `quality` and `names`,
/// the same in every program.
void addQualityOptions(CLI::App& app, Quality& quality, QualityNames& names);
/// After parsing `app`: the options given into `quality`, then the preset's value for every one
/// not given (defocus::resolve); `names` then say what runs.
void finishQuality(const CLI::App& app, QualityNames& names, Quality& quality);

/// --depth-scale, into `scale` (nullopt: the input's usual scale).
void addDepthScaleOption(CLI::App& app, std::optional<double>& scale);

/// Checks the settings the command line gave with defocus::check (an automatic focus, as
/// AutofocusOptions::mode says, is checked once measured): each problem is logged as an error
/// and the result is kExitUsage; nullopt when there is none.
std::optional<int> checkSettings(const Settings& settings);

/// Installs handlers for SIGINT and SIGTERM that only record the signal: the program stops
/// reading, closes its outputs (defocus puts nothing under an output's name then, README "Exit
/// status") and exits with stopStatus().
void catchStopSignals();
/// True once SIGINT or SIGTERM arrived.
bool stopRequested();
/// The signal that arrived (SIGINT or SIGTERM), 0 if none.
int stopSignal();
/// kExitInterrupted (130) after SIGINT, kExitTerminated (143) after SIGTERM, kExitDone if none.
int stopStatus();
/// Test hook: as if `signal` had arrived (0 clears it).
void requestStop(int signal);

/// The exit status for an error that ended a run: kExitUnavailable for defocus::GlError (no EGL
/// display or GL 4.5 context, a shader the driver refuses) or a busy camera (a retry may work),
/// kExitBadInput for everything else (the same input fails again).
int statusFor(const std::exception& error);

} // namespace defocus::cli
