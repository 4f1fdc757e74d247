// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-preview: a live depth-of-field preview with autofocus, keyboard and mouse controls.
//   defocus-preview /dev/video0 --depth depth.png      (webcam + one depth image, fixed camera)
//   defocus-preview /dev/video0 --depth /dev/video2    (colour + Z16 depth camera)
//   defocus-preview data/tum_fr1_rpy --loop            (a recorded clip, at its own pace)
//   defocus-preview data/tum_fr1_rpy --no-window --loop --frames 300 --no-pace  (timing only)
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "defocus/Filter.hpp"
#include "defocus/Focus.hpp"
#include "defocus/Settings.hpp"
#include "samples/CliOptions.hpp"
#include "samples/ExitStatus.hpp"
#include "samples/LiveLoop.hpp"
#include "samples/PreviewController.hpp"
#include "sinks/DisplaySink.hpp"
#include "sources/DepthScale.hpp"
#include "sources/FrameSource.hpp"
#include "sources/ReadAheadSource.hpp"

namespace {

using namespace defocus;

/// The command line. The lens and quality options (lens, quality and their names: model, fov,
/// nearM, farM, qualityPreset, ...) are the ones every program shares (samples/CliOptions.hpp),
/// --quality the balanced preset by default as defocus's. The filtering goes through the public
/// API (include/defocus/), as any program's would.
struct Options : cli::LensNames, cli::QualityNames {
    Lens lens;
    Quality quality;
    std::string input;
    std::string depth;
    std::optional<double> depthScale;
    SourceOptions camera; ///< --size, --camera-fps, --pixel-format
    std::string focus = "auto";
    std::string view = "composite";
    FocusTrackerOptions autofocus;
    std::optional<std::size_t> frames;
    bool loop = false;
    bool exitAtEnd = false;
    bool noPace = false;
    bool noWindow = false;
    bool trace = false;
    std::string screenshotDir = ".";
    bool quiet = false;
    bool verbose = false;
};

bool isVideoDevice(const std::string& path)
{
    return path.rfind("/dev/video", 0) == 0;
}

std::string modelName(Lens::Model model)
{
    return model == Lens::Model::ThinLens ? "thin-lens" : "focal-range";
}

/// --focus: 'auto' (nullopt), 'inf' or metres; false for anything else.
bool parseFocus(const std::string& text, std::optional<double>& focusM)
{
    focusM.reset();
    if (text == "auto")
        return true;
    if (text == "inf" || text == "infinity") {
        focusM = std::numeric_limits<double>::infinity();
        return true;
    }
    try {
        std::size_t used = 0;
        focusM = std::stod(text, &used);
        return used == text.size();
    } catch (const std::logic_error&) {
        return false;
    }
}

int run(const Options& o)
{
    SourceOptions sourceOptions;
    sourceOptions.input = o.input;
    if (!o.depth.empty())
        sourceOptions.depth = o.depth;
    sourceOptions.depthScale = o.depthScale;
    sourceOptions.width = o.camera.width;
    sourceOptions.height = o.camera.height;
    sourceOptions.fps = o.camera.fps;
    sourceOptions.pixelFormat = o.camera.pixelFormat;
    sourceOptions.yuvColor = true; // a camera's YUYV or NV12 goes to the GPU as it came
    std::unique_ptr<FrameSource> source = openSource(sourceOptions);
    // Cameras never block the preview; clips never drop a frame, and are decoded a frame or two
    // ahead on a thread of their own while the filter renders (sources/ReadAheadSource.hpp).
    const bool live = source->isLive() || isVideoDevice(o.input);
    const auto readAhead = [live](std::unique_ptr<FrameSource> opened) -> std::unique_ptr<FrameSource> {
        if (live)
            return opened;
        return ReadAheadSource::onThreads(std::move(opened), ReadAheadSource::defaultThreads());
    };
    source = readAhead(std::move(source));
    const double sourceFps = source->frameRate() > 0.0 ? source->frameRate() : 30.0;

    LiveControls controls;
    controls.lens = o.lens; // finishLens has set its model and field of view
    controls.view = viewNamed(o.view).value_or(Settings::View::Composite); // checked by CLI11
    controls.autofocus = o.focus == "auto";
    FocusTracker autofocus(o.autofocus);
    if (!controls.autofocus)
        autofocus.setFocus(o.lens.focusM);
    // The focal range follows the focus, keeping the ratios given at the start.
    const double rangeFocus = std::isfinite(autofocus.focusM()) ? autofocus.focusM() : 2.0;
    controls.nearRatio = o.nearM.value_or(controls.nearRatio * rangeFocus) / rangeFocus;
    controls.farRatio = o.farM.value_or(controls.farRatio * rangeFocus) / rangeFocus;

    // What the window's keys and clicks do to the controls.
    PreviewController controller(controls);
    // The window before the GL context: a missing display is the likelier failure, and cheap.
    std::unique_ptr<DisplaySink> display;
    if (!o.noWindow)
        display = std::make_unique<DisplaySink>(DisplayOptions{"defocus-preview", o.screenshotDir});
    Settings settings; // the lens and view of each frame from the controls; the focus is the tracker's
    settings.quality = o.quality;
    Filter filter(settings);
    if (!o.quiet)
        spdlog::info("{} ({}) on {}; keys: {}", source->describe(), live ? "live: newest frame, drops counted"
                                                                         : "recorded: every frame",
                     filter.renderer(), kKeyHelp);

    auto feed = std::make_unique<FrameFeed>(*source, live);
    Pacer pacer(1.0 / sourceFps);
    LiveStats stats;
    std::optional<FedFrame> current;
    std::vector<Timings::Pass> gpu;
    std::size_t framesShown = 0, pipelineFrames = 0, renders = 0;
    double pipelineMs = 0.0;
    double previousTimestamp = 0.0;
    bool ended = false, endNoted = false, forceRender = false, captureClock = false;
    std::uint64_t renderedRevision = std::numeric_limits<std::uint64_t>::max();
    std::string lastIssues;
    auto lastStep = LiveClock::now();
    int exitCode = kExitDone;
    bool depthChecked = false;

    cli::catchStopSignals();
    try {
        while (!controls.quit && !cli::stopRequested()) {
            // 1. A new frame, unless paused or at the end.
            bool fresh = false;
            feed->setPaused(controls.paused);
            const bool wantFrame = !ended && !controls.paused && (!o.frames || framesShown < *o.frames);
            if (wantFrame) {
                const auto readStart = LiveClock::now();
                std::optional<FedFrame> fed = feed->next(std::chrono::milliseconds(20));
                if (fed && !live) {
                    // The latency of a clip frame starts when it is read, or when it falls due
                    // if it had to wait for the clip's pace.
                    const auto due = o.noPace ? readStart : pacer.wait(fed->frame.timestampS);
                    fed->origin = std::max(readStart, due);
                }
                if (fed && !depthChecked) {
                    const DepthScaleCheck check = checkDepthScale(
                        fed->frame.depth, o.depthScale.value_or(defaultDepthScale(sourceOptions)), fed->frame.name);
                    depthChecked = check.validPixels > 0;
                    if (!check.warning.empty())
                        spdlog::warn("{}", check.warning);
                }
                if (fed) {
                    const double dt = secondsBetweenFrames(previousTimestamp, fed->frame.timestampS, 1.0 / sourceFps);
                    previousTimestamp = fed->frame.timestampS;
                    if (controls.autofocus)
                        autofocus.update(fed->frame.depth, dt);
                    else
                        autofocus.advance(dt);
                    captureClock = captureClock || fed->fromCaptureClock;
                    current = std::move(fed);
                    fresh = true;
                    lastStep = LiveClock::now();
                } else if (feed->ended()) {
                    if (o.loop && !live && framesShown > 0) {
                        feed.reset();
                        source = readAhead(openSource(sourceOptions));
                        feed = std::make_unique<FrameFeed>(*source, live);
                        previousTimestamp = 0.0;
                        continue;
                    }
                    ended = true;
                }
            }
            if (!ended && o.frames && framesShown >= *o.frames)
                ended = true;
            if (ended && !endNoted) {
                endNoted = true;
                forceRender = true;
                feed->stop(); // a camera past --frames stops capturing (and dropping)
                if (!o.quiet)
                    spdlog::info("end of stream after {} frames{}", framesShown,
                                 display && !o.exitAtEnd ? "; holding the last frame (q quits)" : "");
                if (!display || o.exitAtEnd || !current)
                    break;
            }

            // 2. Requests from the window, and the focus of a held frame.
            if (current && controls.tap) {
                const cv::Size size = colorSize(current->frame);
                autofocus.tap(*controls.tap, static_cast<double>(size.width) / size.height);
                if (!autofocus.retarget(current->frame.depth))
                    spdlog::warn("tap to focus: no valid depth there; the focus stays at {:.2f} m", autofocus.targetM());
                else
                    spdlog::info("tap to focus: target {:.3f} m", autofocus.targetM());
            }
            controls.tap.reset();
            if (current && controls.recentre) {
                autofocus.recentre();
                autofocus.retarget(current->frame.depth);
            }
            controls.recentre = false;
            bool animating = false;
            const auto now = LiveClock::now();
            if (current && !fresh) {
                // A held frame (paused, at the end, or between live frames): the spring runs on
                // wall-clock time so that a tap still glides to its target.
                if (controls.autofocus && controls.revision != renderedRevision)
                    autofocus.retarget(current->frame.depth);
                if (!autofocus.settled()) {
                    autofocus.advance(std::chrono::duration<double>(now - lastStep).count());
                    animating = true;
                }
            }
            lastStep = now;

            // 3. Render and show when anything changed.
            const bool render = current && (fresh || animating || forceRender || controls.revision != renderedRevision);
            if (!render) {
                if (display) {
                    display->poll(live && !controls.paused ? 1 : 15);
                    controller.serve(*display);
                }
                continue;
            }
            forceRender = false;
            std::vector<std::string> issues;
            const Lens lens = lensFor(controls, autofocus.focusM(), &issues);
            std::string issueText;
            for (const auto& issue : issues)
                issueText += (issueText.empty() ? "" : "; ") + issue;
            if (issueText != lastIssues && !issueText.empty())
                spdlog::warn("clamped: {}", issueText);
            lastIssues = issueText;

            settings.lens = lens;
            settings.view = controls.view;
            filter.setSettings(settings); // clamped by lensFor
            const Frame& frame = current->frame;
            const cv::Mat image = filter.process(frame);
            const FrameReport& report = filter.lastFrame();
            const Timings& timings = report.timings;
            if (!timings.gpu.empty())
                gpu = timings.gpu;
            renderedRevision = controls.revision;
            ++renders;
            if (display) {
                HudStatus status;
                status.focusM = autofocus.focusM();
                status.targetM = autofocus.targetM();
                status.autofocus = controls.autofocus;
                status.tapped = autofocus.tapped();
                status.focusWindow = autofocus.region();
                status.lens = lens;
                status.view = controls.view;
                status.fps = stats.recentFps();
                status.latencyMs = stats.recentLatencyMs();
                status.dropped = feed->dropped();
                status.frameIndex = current->frame.index;
                status.paused = controls.paused;
                status.live = live;
                status.ended = ended;
                status.timings = timings;
                status.gpu = gpu;
                if (!issueText.empty()) {
                    status.message = "clamped: " + issueText;
                    status.warning = true;
                }
                controller.setFocusForKeys(autofocus.focusM());
                display->setHud(controller.hud(status, controls.tileMap ? &report.plan : nullptr));
                display->write(image);
                controller.serve(*display);
            }
            if (fresh) {
                stats.frameShown(current->origin, LiveClock::now());
                ++framesShown;
                pipelineMs += timings.totalMs;
                ++pipelineFrames;
            }
            if (o.trace) {
                std::printf("shown frame=%zu new=%d view=%s focus=%.4f target=%.4f af=%d paused=%d ended=%d rev=%llu\n",
                            current->frame.index, fresh ? 1 : 0, std::string(viewName(controls.view)).c_str(),
                            autofocus.focusM(), autofocus.targetM(), controls.autofocus ? 1 : 0,
                            controls.paused ? 1 : 0, ended ? 1 : 0,
                            static_cast<unsigned long long>(controls.revision));
                std::fflush(stdout);
            }
        }
    } catch (const std::exception& error) {
        spdlog::error("frame {}: {}", framesShown, error.what());
        exitCode = cli::statusFor(error);
    }
    feed->stop();
    if (display)
        display->finish();
    if (cli::stopRequested()) {
        spdlog::warn("stopped by {} after {} frames", cli::stopSignal() == SIGINT ? "Ctrl-C" : "SIGTERM", framesShown);
        if (exitCode == kExitDone)
            exitCode = cli::stopStatus();
    }
    if (exitCode == kExitDone && framesShown == 0) {
        spdlog::error("{} gave no frames", o.input);
        return kExitBadInput;
    }

    const char* origin = captureClock ? "capture timestamp" : "read";
    const char* end = display ? "display" : "frame ready (no window)";
    std::printf("defocus-preview: %zu frames shown, %zu dropped, %zu renders; %.1f fps; latency %s -> %s: p50 %.1f ms, "
                "p95 %.1f ms, max %.1f ms; pipeline %.1f ms/frame\n",
                framesShown, feed->dropped(), renders, stats.fps(), origin, end, stats.latencyPercentileMs(0.5),
                stats.latencyPercentileMs(0.95), stats.latencyPercentileMs(1.0),
                pipelineFrames ? pipelineMs / static_cast<double>(pipelineFrames) : 0.0);
    const Lens lens = lensFor(controls, autofocus.focusM());
    std::printf("defocus-preview: final focus %.3f m (%s, target %.3f m), f/%.2f, max CoC %.1f px, %s, view %s\n",
                autofocus.focusM(), controls.autofocus ? "auto" : "manual", autofocus.targetM(), lens.fNumber,
                lens.maxCocPx, modelName(lens.cocModel).c_str(), std::string(viewName(controls.view)).c_str());
    std::fflush(stdout);
    return exitCode;
}

} // namespace

int main(int argc, char** argv)
{
    Options o;
    CLI::App app{"defocus-preview: live depth-of-field preview with autofocus (McIntosh et al. 2012 hexagonal "
                 "bokeh).\nINPUT is a camera (/dev/videoN), a video file, a TUM RGB-D folder, a folder of colour "
                 "images or one image; --depth gives its depth (a file, a folder, a TUM depth.txt or a Z16 camera "
                 "/dev/videoN).\nKeys: " +
                 std::string(kKeyHelp)};
    cli::addVersionFlag(app, "defocus-preview");
    app.add_option("input", o.input, "Colour input: /dev/videoN, video file, TUM folder, image folder or image")
        ->required();
    app.add_option("--depth", o.depth, "Depth for INPUT: one image (fixed camera), a folder, depth.txt, or /dev/videoN");
    cli::addDepthScaleOption(app, o.depthScale);
    cli::addCameraOptions(app, o.camera);
    app.add_option("--frames", o.frames, "Stop reading after this many frames")->check(cli::atLeast(1));
    app.add_option("--focus", o.focus,
                   "'auto' (autofocus on; click to focus) or a distance in metres / 'inf' (autofocus off)")
        ->capture_default_str();
    cli::addLensOptions(app, o.lens, o, cli::FocalRange::FollowsFocus);
    cli::addQualityOptions(app, o.quality, o);
    std::vector<std::string> views;
    for (const Settings::View v : kViews)
        views.emplace_back(viewName(v));
    app.add_option("--view", o.view, "View at the start: " + fmt::format("{}", fmt::join(views, ", ")))
        ->check(CLI::IsMember(views))
        ->capture_default_str();
    app.add_option("--tau", o.autofocus.timeConstantS, "Autofocus time constant, seconds (critically damped), >= 0")
        ->check(cli::atLeast(0))
        ->capture_default_str();
    app.add_option("--af-window", o.autofocus.windowFraction, "Autofocus centre window, fraction of each axis, (0, 1]")
        ->check(cli::between(1e-3, 1.0))
        ->capture_default_str();
    app.add_option("--af-dead-band", o.autofocus.deadBandDioptres,
                   "Autofocus dead band, dioptres: smaller changes of the measured depth are ignored")
        ->check(cli::atLeast(0))
        ->capture_default_str();
    app.add_flag("--loop", o.loop, "Play a recorded clip again and again");
    app.add_flag("--exit-at-end", o.exitAtEnd, "Quit at the end of a clip (or after --frames) instead of holding");
    app.add_flag("--no-pace", o.noPace, "Play a recorded clip as fast as it can be processed, not at its own rate");
    app.add_flag("--no-window", o.noWindow, "No window: process and print the figures (for timing; exits at the end)");
    app.add_flag("--trace", o.trace, "Print one line per picture shown (view, focus, state) on stdout, for tests");
    app.add_option("--screenshot-dir", o.screenshotDir, "Where the s key writes defocus-preview-NNNN.png")
        ->capture_default_str();
    app.add_flag("-q,--quiet", o.quiet, "Only the summary and errors");
    app.add_flag("-v,--verbose", o.verbose, "Debug logging");
    if (const auto status = cli::parse(app, argc, argv))
        return *status;
    cli::logToStderr("defocus-preview", o.quiet, o.verbose);

    try {
        cli::finishQuality(app, o, o.quality);
        cli::finishLens(o, o.lens);
        std::optional<double> focusM;
        if (!parseFocus(o.focus, focusM)) {
            spdlog::error("--focus '{}' is not a distance in metres, 'inf' or 'auto'", o.focus);
            return kExitUsage;
        }
        if (focusM)
            o.lens.focusM = *focusM;
        // --near and --far are checked at the starting focus (2 m with auto or inf), where run()
        // takes their ratios to the focus from.
        const double startM = std::isfinite(o.lens.focusM) ? o.lens.focusM : 2.0;
        const LiveControls defaults;
        o.lens.nearM = o.nearM.value_or(defaults.nearRatio * startM);
        o.lens.farM = o.farM.value_or(defaults.farRatio * startM);
        // The command line is checked strictly, like defocus's; keys later clamp with a warning.
        Settings given;
        given.lens = o.lens;
        given.quality = o.quality;
        if (!focusM)
            given.autofocus.mode = AutofocusOptions::Mode::FirstFrame; // the focus is checked once measured
        if (const auto status = cli::checkSettings(given))
            return *status;
        return run(o);
    } catch (const std::exception& error) {
        spdlog::error("{}", error.what());
        return cli::statusFor(error);
    }
}
