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

#include "filter/Settings.hpp"
#include "samples/ExitStatus.hpp"
#include "sources/FrameSource.hpp"

namespace defocus::cli {

/// Parses the command line. --help and --version print to standard output and give 0; any
/// parse error (unknown option, bad value, value out of range, missing argument) prints one line
/// "PROGRAM: error: MESSAGE (see --help)" to standard error and gives kExitUsage. nullopt: go on.
std::optional<int> parse(CLI::App& app, int argc, char** argv);

/// Sends every log line (spdlog's default logger) to standard error as "PROGRAM: LEVEL: ...";
/// standard output keeps only results. quiet: warnings and errors only; verbose: debug too.
void logToStderr(std::string_view program, bool quiet = false, bool verbose = false);

/// One line on standard error, "PROGRAM: error: MESSAGE", for use before logToStderr.
void printError(std::string_view program, std::string_view message);

/// The camera options, the same wherever a camera can be opened: --size WxH, --camera-fps and
/// --pixel-format, into `source` (its width, height, fps and pixelFormat).
void addCameraOptions(CLI::App& app, SourceOptions& source);

/// Checks the lens and quality the command line gave (validateCommandLine): each problem is
/// logged as an error and the result is kExitUsage; nullopt when there is none.
std::optional<int> checkLensAndQuality(const LensSettings& lens, const QualitySettings& quality, bool autoFocus);

/// Installs handlers for SIGINT and SIGTERM that only record the signal: the program stops
/// reading, finalises what it has written and exits with stopStatus().
void catchStopSignals();
/// True once SIGINT or SIGTERM arrived.
bool stopRequested();
/// The signal that arrived (SIGINT or SIGTERM), 0 if none.
int stopSignal();
/// kExitInterrupted (130) after SIGINT, kExitTerminated (143) after SIGTERM, kExitDone if none.
int stopStatus();
/// Test hook: as if `signal` had arrived (0 clears it).
void requestStop(int signal);

/// The exit status for an error that ended a run: kExitUnavailable for no EGL display/GL 4.5
/// context, a shader the driver refuses or a busy camera (a retry may work), kExitBadInput for
/// everything else (the same input fails again).
int statusFor(const std::exception& error);

} // namespace defocus::cli
