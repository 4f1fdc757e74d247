// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus: gives recorded RGB-D footage the depth of field of a real lens, with polygonal or round bokeh.
//   defocus data/tum_fr1_rpy -o out/tum.mp4 --focus 1.2 --f-number 1.4
//   defocus photo.png --depth depth.png --depth-scale 1000 -o out.png --view coc
//   defocus --info
// The flow: parse the command line (declareOptions, finishOptions) -> runClip(options, filter),
// which opens the input and output and hands them to processClip. The settings and the filtering
// go through the library's public API (defocus::Settings, defocus::Filter, include/defocus/): one
// Filter, its GL context and shaders, is made once and serves several clips (--batch). The
// command line's parsing (CLI11), the sources and the sinks are the tree's own, and so is the
// focus control (FocusSchedule, over the public FocusTracker); --demo's synthetic scene is
// libdefocus' (defocus::Source). Nothing of filter/ is included (the build checks it). Results
// go to standard output, diagnostics to standard error; the exit statuses are ExitStatus.hpp's.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <system_error>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "defocus/Filter.hpp"
#include "defocus/Focus.hpp"
#include "defocus/Settings.hpp"
#include "defocus/Source.hpp"
#include "samples/Batch.hpp"
#include "samples/CliOptions.hpp"
#include "samples/ExitStatus.hpp"
#include "samples/FocusSchedule.hpp"
#include "samples/NewestFrameSource.hpp"
#include "samples/Progress.hpp"
#include "sinks/BackgroundSink.hpp"
#include "sinks/FrameSink.hpp"
#include "sinks/ImageSinks.hpp"
#include "sinks/V4l2OutputSink.hpp"
#include "sources/DepthScale.hpp"
#include "sources/FrameSource.hpp"
#include "sources/ReadAheadSource.hpp"

namespace {

using namespace defocus;

/// The command line. The lens and quality options and their names (model, fov, qualityPreset,
/// nearField, kernel, precision, resolution: as given, then as resolved, the report's words) are
/// the ones every program shares (samples/CliOptions.hpp).
struct Options : cli::LensNames, cli::QualityNames {
    std::string input;
    std::string output;
    std::string depth;
    std::optional<double> depthScale;
    std::string focus = "auto";
    /// The lens and quality (every field resolved by finishOptions), the view; the output's
    /// encoding is the sink's, the focus is set frame by frame.
    Settings settings;
    std::string view = "composite";
    std::string contactSheet;
    std::size_t contactFrame = 0;
    std::optional<std::size_t> frames; ///< frames out at most
    std::size_t start = 0;             ///< input frames skipped first
    std::size_t every = 1;             ///< then every Nth input frame
    std::string focusPoint;            ///< --focus-point X,Y; "" = the centre
    FocusTrackerOptions autofocus;     ///< --focus track: --tau
    double depthScaleUsed = 0.0;       ///< the scale the input is read at (for the plausibility check)
    SourceOptions camera;              ///< --size, --camera-fps, --pixel-format
    std::optional<double> fps;
    std::string timings;
    bool explain = false;
    bool info = false;
    bool demo = false; ///< a synthetic clip instead of INPUT
    std::string demoScene = "spheres";
    bool quiet = false;
    bool verbose = false;
    double progressInterval = 5.0; ///< --progress-interval, seconds
    bool overwrite = false;   ///< -y: replace outputs that exist
    bool keepPartial = false; ///< --keep-partial: a failed or stopped run's frames as OUTPUT.partial
    std::string codec;        ///< --codec, "" = the container's default
    std::string imageFormat = "png"; ///< --image-format of a folder output
    // Many clips (samples/Batch.hpp) and the GPU.
    std::string batch;         ///< --batch MANIFEST
    std::string shard;         ///< --shard I/N, "" = the Slurm array task's, else 0/1
    bool redo = false;
    std::string reportDir;
    std::size_t inFlight = 1;
    std::size_t readThreads = 0; ///< --read-threads; 0 = ReadAheadSource::defaultThreads()
    std::size_t writeThreads = 0; ///< --write-threads; 0 = the same default
    std::optional<int> eglDevice;
    std::string report;        ///< --report FILE.json of a single run
};

/// A --read-threads or --write-threads value: 0 is the CPUs this process may use less one.
std::size_t threadsOrDefault(std::size_t threads)
{
    return threads > 0 ? threads : ReadAheadSource::defaultThreads();
}

ContextOptions contextOptions(const Options& options)
{
    ContextOptions context;
    context.eglDevice = options.eglDevice;
    return context;
}

int printInfo(const Options& options)
{
    for (const auto& d : eglDevices())
        fmt::print("EGL device {}: {}{}{}\n", d.index, d.software ? "software" : "hardware",
                   d.drmFile.empty() ? "" : ", " + d.drmFile, d.cudaId ? fmt::format(", CUDA device {}", *d.cudaId) : "");
    const RendererInfo info = probeRenderer(contextOptions(options));
    const std::size_t cpus = ReadAheadSource::usableCpus();
    const std::size_t threads = threadsOrDefault(options.readThreads), writing = threadsOrDefault(options.writeThreads);
    fmt::print("EGL platform: {}{}\nEGL vendor:   {}\nEGL version:  {}\nGL vendor:    {}\nGL renderer:  {}\n"
               "GL version:   {}\nGPU timers:   {}\nDepth prep:   {}\nPrecision:    {} (the presets', the renderer's)\n"
               "Passes:       {} shaders\nReading:      {} thread{} ahead of the filter ({} CPU{} this process may use)\n"
               "Writing:      {} thread{} encoding a folder output's frames behind the filter\n",
               info.platform, info.eglDevice >= 0 ? fmt::format(" (EGL device {})", info.eglDevice) : "", info.eglVendor,
               info.eglVersion, info.glVendor, info.glRenderer, info.glVersion, info.timerQueries ? "yes" : "no",
               info.depthPrepOnGpu ? "GPU" : "CPU", info.halfFloatTargets ? "16f" : "32f",
               info.computePasses ? "compute" : "fragment", threads, threads == 1 ? "" : "s", cpus, cpus == 1 ? "" : "s",
               writing, writing == 1 ? "" : "s");
    return kExitDone;
}

/// GPU milliseconds summed per pass, in the order the passes first reported (the order they run).
class PassTotals {
public:
    void add(const std::string& name, double ms)
    {
        const auto found = std::find_if(totals_.begin(), totals_.end(), [&](const auto& t) { return t.first == name; });
        if (found == totals_.end())
            totals_.emplace_back(name, ms);
        else
            found->second += ms;
    }
    const std::vector<std::pair<std::string, double>>& totals() const { return totals_; }

private:
    std::vector<std::pair<std::string, double>> totals_;
};

std::string summarise(std::size_t in, std::size_t out, const PassTotals& passMs, double totalMs, double uploadMs,
                      double readbackMs, std::size_t timed)
{
    const double n = static_cast<double>(std::max<std::size_t>(timed, 1));
    std::string passes;
    for (const auto& [name, ms] : passMs.totals())
        passes += fmt::format("{}{} {:.1f}", passes.empty() ? "" : ", ", name, ms / n);
    return fmt::format("defocus: {} frames in, {} frames out, {:.1f} ms/frame (GPU per pass: {}; upload {:.1f}, "
                       "readback {:.1f} ms)",
                       in, out, totalMs / n, passes.empty() ? "n/a" : passes, uploadMs / n, readbackMs / n);
}

/// Per-frame timings for --timings, and their p50/p95/max summary.
class TimingLog {
public:
    /// Frame `index` of the clip, the filter's frame `filterIndex` (Timings::gpuFrame counts those).
    void frame(const Timings& t, std::size_t index, std::size_t filterIndex)
    {
        filterIndex_.push_back(filterIndex);
        frames_.push_back({{"index", index},
                           {"total_ms", t.totalMs},
                           {"depth_prep_ms", t.depthPrepMs},
                           {"analysis_ms", t.analysisMs},
                           {"upload_ms", t.uploadMs},
                           {"render_ms", t.renderMs},
                           {"readback_ms", t.readbackMs},
                           {"gpu_ms", nlohmann::json::object()}});
        if (!t.gpu.empty())
            gpu(t.gpu, t.gpuFrame);
    }
    /// GPU times arrive one frame late; they go to the frame they measured, the filter's frame
    /// `filterIndex`.
    void gpu(const std::vector<Timings::Pass>& passes, std::size_t filterIndex)
    {
        for (std::size_t i = 0; i < frames_.size(); ++i)
            if (filterIndex_[i] == filterIndex)
                for (const auto& pass : passes)
                    frames_[i]["gpu_ms"][pass.name] = pass.ms;
    }
    /// p50/p95/max of each timing and each pass over the frames so far.
    nlohmann::json summary() const
    {
        nlohmann::json summary = nlohmann::json::object();
        const auto stats = [](std::vector<double> v) {
            std::sort(v.begin(), v.end());
            const auto at = [&](double q) { return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)]; };
            return nlohmann::json{{"p50", at(0.5)}, {"p95", at(0.95)}, {"max", v.back()}, {"frames", v.size()}};
        };
        for (const char* key : {"total_ms", "depth_prep_ms", "analysis_ms", "upload_ms", "render_ms", "readback_ms"}) {
            std::vector<double> v;
            for (const auto& f : frames_)
                v.push_back(f[key].get<double>());
            if (!v.empty())
                summary[key] = stats(v);
        }
        std::map<std::string, std::vector<double>> passes;
        for (const auto& f : frames_)
            for (const auto& [name, ms] : f["gpu_ms"].items())
                passes[name].push_back(ms.get<double>());
        for (const auto& [name, v] : passes)
            summary["gpu_ms"][name] = stats(v);
        return summary;
    }
    void write(const std::string& file, const std::string& renderer, cv::Size size) const
    {
        const nlohmann::json doc{{"renderer", renderer},
                                 {"width", size.width},
                                 {"height", size.height},
                                 {"summary", summary()},
                                 {"frames", frames_}};
        writeFileAtomically(file, doc.dump(2) + "\n");
    }

private:
    std::vector<nlohmann::json> frames_;
    std::vector<std::size_t> filterIndex_; ///< the filter's frame number of each of frames_
};

/// --demo: a synthetic scene's shot (docs/synthetic.md) through the command line's lens, rendered
/// by libdefocus (defocus::Source, in a GL context of its own); with 'auto' focus, the focus
/// follows the scene's focus pull.
class DemoSource final : public FrameSource {
public:
    explicit DemoSource(const Options& options) : source_(settingsFor(options)) {}
    std::optional<Frame> next() override { return source_.next(); }
    std::optional<std::size_t> frameCount() const override { return source_.frameCount(); }
    double frameRate() const override { return source_.frameRate(); }
    std::string describe() const override { return source_.describe(); }
    /// The focus of the scene's pull at frame `index`; nullopt without a pull.
    std::optional<double> sceneFocusM(std::size_t index) const { return source_.sceneFocusM(index); }

private:
    static SourceSettings settingsFor(const Options& options)
    {
        SourceSettings settings;
        SyntheticClip clip;
        clip.scene = options.demoScene;
        clip.frames = options.frames.value_or(60);
        clip.lens = options.settings.lens;
        clip.focusPull = options.focus == "auto";
        settings.synthetic = clip;
        settings.context = contextOptions(options);
        return settings;
    }
    defocus::Source source_;
};

/// What a clip's report says of it (--report, --batch): frames, the settings as resolved, the
/// renderer, and the timings' p50/p95/max.
void fillReport(nlohmann::json& r, const Options& options, const Lens& lens, const RendererInfo& info,
                std::size_t framesIn, const FrameSink& sink, const TimingLog& timingLog)
{
    r["frames_in"] = framesIn;
    r["frames_out"] = sink.framesWritten();
    r["output"] = sink.describe();
    r["renderer"] = {{"platform", info.platform},     {"egl_device", info.eglDevice}, {"egl_vendor", info.eglVendor},
                     {"egl_version", info.eglVersion}, {"gl_vendor", info.glVendor}, {"gl_renderer", info.glRenderer},
                     {"gl_version", info.glVersion}};
    r["settings"] = {{"focus", options.focus},
                     {"focus_m", lens.focusM},
                     {"f_number", lens.fNumber},
                     {"focal_length_mm", lens.focalLengthMm},
                     {"sensor_width_mm", lens.sensorWidthMm},
                     {"fov_from", options.fov},
                     {"max_coc_px", lens.maxCocPx},
                     {"coc_model", options.model},
                     {"near_m", lens.nearM},
                     {"far_m", lens.farM},
                     {"blades", lens.blades},
                     {"blade_rotation_deg", lens.bladeRotationDeg},
                     {"aperture_ratio", lens.apertureRatio},
                     {"quality", options.qualityPreset},
                     {"samples", options.settings.quality.samples.value_or(0)},
                     {"hexagon", options.kernel},
                     {"precision", options.precision},
                     {"resolution", options.resolution},
                     {"near_field", options.settings.quality.nearField.value_or(false)},
                     {"highlight_sprites", options.settings.quality.highlightSprites},
                     {"highlight_gain", options.settings.quality.highlightGain},
                     {"adaptive", !options.settings.quality.alwaysOn},
                     {"view", options.view},
                     {"frames", options.frames ? nlohmann::json(*options.frames) : nlohmann::json()}};
    r["timings_ms"] = timingLog.summary();
}

/// A request the first frame shows the input cannot meet (--focus-point outside it): the clip
/// ends there, before any frame is written, in one line from the caller (status 1 as bad input).
class RequestError : public std::invalid_argument {
public:
    using std::invalid_argument::invalid_argument;
};

/// How many frames the clip gives out of `count` input frames after --start, --every and --frames;
/// with `count` unknown (a camera, a stream), at most --frames, or nullopt without it.
std::optional<std::size_t> framesOut(const Options& options, std::optional<std::size_t> count)
{
    if (!count)
        return options.frames;
    const std::size_t taken = *count > options.start ? (*count - options.start + options.every - 1) / options.every : 0;
    return options.frames ? std::min(taken, *options.frames) : taken;
}

/// True for an output of one picture (FILE.png, .jpg, .exr): FrameSink.hpp's SingleImageSink.
bool isOneImage(const std::string& output)
{
    std::error_code ec;
    if (output.empty() || output.back() == '/' || std::filesystem::is_directory(output, ec))
        return false;
    std::string ext = std::filesystem::path(output).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".exr";
}

/// Requests that the clip's length rules out, refused before any frame is rendered (exit status
/// 1 through cli::statusFor): a one-image output of a clip of several frames (it would keep the
/// last and drop the others), and a --contact-frame the clip never gives. `count`: the source's
/// frame count, nullopt when it cannot say.
void checkAgainstTheClip(const Options& options, std::optional<std::size_t> count)
{
    const std::string input = options.demo ? std::string("--demo") : fmt::format("'{}'", options.input);
    if (isOneImage(options.output)) {
        const std::optional<std::size_t> out = framesOut(options, count);
        const std::filesystem::path stem = std::filesystem::path(options.output).replace_extension();
        const std::string instead = fmt::format("write them to a folder (-o '{}/') or a video (-o '{}.mp4'), or "
                                                "take one frame with --start N --frames 1",
                                                stem.string(), stem.string());
        if (!out)
            throw SinkError(fmt::format("-o '{}' holds one image but {} gives frames until it ends: {}",
                                        options.output, input, instead));
        if (*out > 1)
            throw SinkError(fmt::format("-o '{}' holds one image but {} gives {} frames: {}", options.output, input,
                                        *out, instead));
    }
    if (options.contactSheet.empty())
        return;
    const std::size_t frame = options.contactFrame;
    if (count && frame >= *count)
        throw std::invalid_argument(fmt::format("--contact-frame {} is beyond the {} frames of {} (0 to {})", frame,
                                                *count, input, *count - 1));
    const bool taken = frame >= options.start && (frame - options.start) % options.every == 0 &&
                       (!options.frames || (frame - options.start) / options.every < *options.frames);
    if (!taken)
        throw std::invalid_argument(fmt::format("--contact-frame {} is not among the frames --start {} --every {}{} "
                                                "take ({}, {}, ...)",
                                                frame, options.start, options.every,
                                                options.frames ? fmt::format(" --frames {}", *options.frames) : "",
                                                options.start, options.start + options.every));
}

/// The frames of one clip from `source` through the pipeline into `sink`; returns the exit status.
/// Only a clip that is done puts its output under the final name (sink.finish()). One stopped by
/// SIGINT/SIGTERM or failed at an error abandons it: nothing is written there, and with
/// --keep-partial the frames so far are kept under OUTPUT.partial (FrameSink.hpp). A camera has no
/// end: SIGINT/SIGTERM ends its clip, which is then done.
int processClip(const Options& options, FrameSource& source, const DemoSource* demo, FrameSink& sink, Filter& filter,
                nlohmann::json* report)
{
    const Settings::Output output =
        sink.encoding() == SinkEncoding::Linear32F ? Settings::Output::Linear32F : Settings::Output::Srgb8;

    Progress progress(framesOut(options, source.frameCount()), !options.quiet,
                      std::chrono::duration<double>(options.progressInterval));

    Settings settings = options.settings;
    settings.output = output;
    if (options.depthScaleUsed > 0.0)
        settings.depthScale = options.depthScaleUsed; // 16-bit depth goes to the filter as it was read
    Lens& lens = settings.lens; // its focus is set frame by frame
    bool settingsGiven = false; // given to the filter with the first frame's focus
    filter.reset();             // a new clip: frame 0 again
    std::optional<cv::Point2d> point;
    if (!options.focusPoint.empty())
        point = parsePoint(options.focusPoint); // checked by finishOptions
    FocusControl focus(options.focus, point, options.autofocus);
    if (!options.quiet && !demo)
        spdlog::info("focus: {}", focus.describe());
    const double fps = source.frameRate() > 0.0 ? source.frameRate() : 30.0;
    std::optional<double> firstTimestamp;
    double previousTimestamp = 0.0;
    std::size_t read = 0;         // input frames read, selected or not
    bool depthChecked = false;
    TimingLog timingLog;
    cv::Size frameSize;
    PassTotals passMs;
    double totalMs = 0, uploadMs = 0, readbackMs = 0;
    std::size_t framesIn = 0, timed = 0;
    cv::Mat sheet; // --contact-sheet's image, once its frame has passed
    std::size_t current = 0; // the input's frame being read or processed, counted as --start counts, for messages

    // Frames in flight (Filter::submit/receive): while one is on its way back from the GPU the
    // next is read and prepared. A camera's frames go one at a time (a frame in flight would be
    // a frame of latency), and so does the contact sheet's frame (it is processed again).
    const std::size_t inFlight = source.isLive() ? 1 : Filter::kFramesInFlight;
    struct Waiting {
        Frame frame;
        double focusM = 0.0;
    };
    std::deque<Waiting> waiting; // submitted, in order
    // A frame back from the filter: to the sink, the explanation, the timings, the progress.
    const auto deliver = [&](const cv::Mat& image, const Waiting& w) {
        if (options.explain)
            std::printf("frame %zu: focus %.4f m\n", w.frame.index, w.focusM);
        sink.writeFrame(image, w.frame);
        frameSize = image.size();
        const FrameReport& done = filter.lastFrame();
        if (options.explain)
            std::printf("frame %zu: %s\n", w.frame.index, done.plan.explain.c_str());
        const Timings& t = done.timings;
        timingLog.frame(t, w.frame.index, done.index);
        for (const auto& pass : t.gpu)
            passMs.add(pass.name, pass.ms);
        totalMs += t.totalMs;
        uploadMs += t.uploadMs;
        readbackMs += t.readbackMs;
        progress.update(++timed);
    };
    const auto receiveOne = [&] {
        const std::optional<cv::Mat> image = filter.receive();
        deliver(*image, waiting.front());
        waiting.pop_front();
    };
    const auto receiveAll = [&] {
        while (!waiting.empty())
            receiveOne();
    };

    int status = kExitDone;
    try {
        while (!cli::stopRequested() && (!options.frames || framesIn < *options.frames)) {
            current = read;
            std::optional<Frame> frame = source.next();
            if (!frame)
                break;
            const std::size_t position = read++;
            if (!firstTimestamp)
                firstTimestamp = frame->timestampS;
            if (position < options.start || (position - options.start) % options.every != 0)
                continue; // --start, --every
            ++framesIn;
            if (const cv::Size size = colorSize(*frame);
                point && framesIn == 1 && !(point->x < size.width && point->y < size.height)) // parsePoint: not negative
                throw RequestError(fmt::format("--focus-point {} is outside the {}x{} frame (X 0 to {}, Y 0 to {})",
                                               options.focusPoint, size.width, size.height, size.width - 1,
                                               size.height - 1));
            if (focus.readsDepth() && frame->depthScale > 0.0) {
                // Metres once, for the focus and then the filter, not once for each.
                frame->depth = depthMetres(*frame);
                frame->depthScale = 0.0;
            }
            if (!depthChecked && !demo && options.depthScaleUsed > 0.0) {
                const DepthScaleCheck check = checkDepthScale(depthMetres(*frame), options.depthScaleUsed, frame->name);
                depthChecked = check.validPixels > 0;
                if (!check.warning.empty())
                    spdlog::warn("{}", check.warning);
            }
            // Seconds since the clip's first frame, for focus keys: its timestamps when it has
            // them, else the frame's index at the frame rate.
            const bool stamped = *firstTimestamp > 0.0 && frame->timestampS > 0.0;
            const double timeS = stamped ? frame->timestampS - *firstTimestamp : static_cast<double>(frame->index) / fps;
            const double dtS = secondsBetweenFrames(previousTimestamp, frame->timestampS, static_cast<double>(options.every) / fps);
            previousTimestamp = frame->timestampS;
            if (const auto pulled = demo ? demo->sceneFocusM(frame->index) : std::nullopt) {
                lens.focusM = *pulled; // the scene's focus pull
            } else if (!focus.isFixed()) {
                lens.focusM = focus.focusFor(*frame, timeS, dtS);
                if (framesIn == 1 && options.focus == "auto" && !options.quiet)
                    spdlog::info("focus: auto -> {:.2f} m (median depth around {} of {})", lens.focusM,
                                 point ? options.focusPoint : std::string("the centre"), frame->name);
                if (const auto issues = check(settings); !issues.empty())
                    throw std::runtime_error(fmt::format("focus {:.3f} m at frame {}: {}", lens.focusM, frame->index,
                                                         issues.front()));
            }
            if (!settingsGiven || lens.focusM != filter.settings().lens.focusM) {
                filter.setSettings(settings); // checked: by finishOptions, or above
                settingsGiven = true;
            }
            const bool sheetFrame = !options.contactSheet.empty() && frame->index == options.contactFrame;
            if (sheetFrame || inFlight == 1) {
                receiveAll();
                const cv::Mat image = filter.process(*frame);
                if (sheetFrame)
                    sheet = filter.contactSheet(); // written with the output, when the run is done
                deliver(image, {std::move(*frame), lens.focusM});
            } else {
                filter.submit(*frame);
                waiting.push_back({std::move(*frame), lens.focusM});
                if (filter.framesInFlight() >= inFlight)
                    receiveOne();
            }
        }
        receiveAll(); // the end of the clip, or a camera stopped: every frame in is a frame out
    } catch (const RequestError&) {
        progress.finish();
        throw;
    } catch (const std::exception& error) {
        progress.finish();
        // A write that failed on the writing thread is rethrown frames later: name its frame.
        if (const auto* background = dynamic_cast<const BackgroundSink*>(&sink))
            if (const std::optional<std::size_t> written = background->failedFrame())
                current = options.start + *written * options.every; // the k-th frame written, as read
        // The frames in flight came through before the error: they go with those written before.
        try {
            receiveAll();
        } catch (const std::exception&) {
            // The sink or the filter fails again: what was written stays as it is.
        }
        spdlog::error("frame {}: {}", current, error.what());
        status = cli::statusFor(error);
        if (report)
            (*report)["error"] = fmt::format("frame {}: {}", current, error.what());
    }
    // A camera's clip ends when it is stopped; any other stopped clip is unfinished.
    const bool cameraEnded = cli::stopRequested() && source.isLive() && status == kExitDone;
    if (cli::stopRequested() && !cameraEnded)
        status = cli::stopStatus();
    // checkAgainstTheClip refused it up front where the clip's length was known.
    if (!options.contactSheet.empty() && sheet.empty() && status == kExitDone && !cli::stopRequested()) {
        spdlog::error("--contact-frame {} is beyond the {} frames read: no contact sheet written to {}",
                      options.contactFrame, read, options.contactSheet);
        status = kExitBadInput;
    }
    if (status == kExitDone && framesIn > 0) {
        try {
            sink.finish();
        } catch (const std::exception& error) {
            spdlog::error("{}", error.what());
            status = cli::statusFor(error);
        }
    }
    std::filesystem::path kept;
    if (status != kExitDone || framesIn == 0) {
        try {
            kept = sink.abandon(options.keepPartial);
        } catch (const std::exception& error) {
            spdlog::error("{}", error.what());
        }
    }
    progress.finish();
    const auto lastGpu = filter.finishGpuTimings();
    if (framesIn > 0)
        timingLog.gpu(lastGpu, filter.lastFrame().index);
    for (const auto& pass : lastGpu)
        passMs.add(pass.name, pass.ms);
    // The contact sheet and the timings stand under their names only when the run is done, as
    // the output does; --keep-partial keeps a failed or stopped run's under NAME.partial.EXT.
    const bool done = status == kExitDone && framesIn > 0;
    const auto sideFile = [&](const std::string& file) {
        return done ? std::filesystem::path(file) : partialPath(file);
    };
    try {
        if (!sheet.empty() && (done || options.keepPartial))
            writeImageAtomically(sideFile(options.contactSheet), sheet);
        if (!options.timings.empty() && framesIn > 0 && (done || options.keepPartial))
            timingLog.write(sideFile(options.timings).string(), filter.renderer(), frameSize);
    } catch (const std::exception& error) {
        spdlog::error("{}", error.what());
        if (status == kExitDone)
            status = cli::statusFor(error);
    }
    const char* signalName = cli::stopSignal() == SIGINT ? "Ctrl-C" : "SIGTERM";
    if (cameraEnded && !options.quiet)
        spdlog::info("{} ended the camera's clip after {} frames", signalName, framesIn);
    if (cli::stopRequested() && !cameraEnded)
        spdlog::warn("stopped by {} after {} frames: {}", signalName, framesIn,
                     !kept.empty()       ? fmt::format("the frames so far are in {}, not {}", kept.string(), options.output)
                     : options.keepPartial ? std::string("no frame written, nothing kept")
                                           : fmt::format("nothing written to {} (--keep-partial keeps the frames so far)",
                                                         options.output));
    else if (!kept.empty())
        spdlog::warn("the frames before the error are in {}, not {}", kept.string(), options.output);
    if (report)
        fillReport(*report, options, lens, filter.rendererInfo(), framesIn, sink, timingLog);
    if (status == kExitDone && framesIn == 0) {
        spdlog::error("{} gave no frames", options.input);
        if (report)
            (*report)["error"] = fmt::format("{} gave no frames", options.input);
        return kExitBadInput;
    }
    std::fflush(stdout);
    std::puts(summarise(framesIn, sink.framesWritten(), passMs, totalMs, uploadMs, readbackMs, timed).c_str());
    if (!options.quiet && status == kExitDone)
        spdlog::info("wrote {}", sink.describe());
    return status;
}

/// One clip, from INPUT (or --demo) to -o OUTPUT: opens the input, the filter when `filter` holds
/// none yet (so a bad input is reported before GL is needed), the output, and runs processClip.
/// Throws for an input, output or GL that cannot be opened (cli::statusFor gives the status).
int runClip(Options options, std::optional<Filter>& filter, nlohmann::json* report = nullptr)
{
    // Outputs besides the main one are checked before any frame is processed.
    if (!options.contactSheet.empty())
        refuseExisting(options.contactSheet, options.overwrite);
    if (!options.timings.empty())
        refuseExisting(options.timings, options.overwrite);

    std::unique_ptr<FrameSource> source;
    DemoSource* demo = nullptr;
    if (options.demo) {
        auto synthetic = std::make_unique<DemoSource>(options);
        demo = synthetic.get();
        source = std::move(synthetic);
    } else {
        SourceOptions sourceOptions = options.camera;
        sourceOptions.input = options.input;
        sourceOptions.depthScale = options.depthScale;
        sourceOptions.depthUnits = true;
        sourceOptions.yuvColor = true; // a camera's YUYV or NV12 goes to the GPU as it came
        if (!options.depth.empty())
            sourceOptions.depth = options.depth;
        source = openSource(sourceOptions);
        options.depthScaleUsed = options.depthScale.value_or(defaultDepthScale(sourceOptions));
    }
    // The outputs' folders after the input (whose errors come first), before GL (openSink checks
    // the main output's again).
    std::error_code ec;
    requireParentFolder(options.output, options.output.back() == '/' || std::filesystem::is_directory(options.output, ec));
    for (const std::string* file : {&options.contactSheet, &options.timings})
        if (!file->empty())
            requireParentFolder(*file, false);
    checkAgainstTheClip(options, source->frameCount());

    if (!filter)
        filter.emplace(Settings{}, contextOptions(options));

    SinkOptions sinkOptions;
    sinkOptions.output = options.output;
    sinkOptions.fps = options.fps.value_or(source->frameRate() > 0 ? source->frameRate() : 30.0);
    sinkOptions.linearSequence = options.imageFormat == "exr";
    sinkOptions.overwrite = options.overwrite;
    sinkOptions.codec = options.codec;
    sinkOptions.threads = threadsOrDefault(options.writeThreads);
    std::unique_ptr<FrameSink> sink = openSink(sinkOptions);
    if (const auto* sequence = dynamic_cast<ImageSequenceSink*>(sink.get()))
        spdlog::debug("encoding the frames on {} thread{}", sequence->threads(), sequence->threads() == 1 ? "" : "s");
    // While the filter works, a file output is encoded and written up to two frames behind on a
    // thread of its own (a folder's frames side by side on --write-threads threads behind it),
    // and a recorded clip decoded ahead on --read-threads threads, one frame more than threads
    // ahead (docs/benchmarks.md, "Reading and writing beside the filter"); not a
    // virtual camera's frames (due when made), nor --demo's (rendered on the GPU the filter uses,
    // one call after the other).
    const bool virtualCamera = dynamic_cast<V4l2OutputSink*>(sink.get()) != nullptr;
    if (!virtualCamera)
        sink = std::make_unique<BackgroundSink>(std::move(sink));
    if (!source->isLive() && !demo) {
        const std::size_t threads = threadsOrDefault(options.readThreads);
        source = ReadAheadSource::onThreads(std::move(source), threads);
        spdlog::debug("reading ahead on {} thread{}", threads, threads == 1 ? "" : "s");
    }
    // A camera to a virtual camera: never make the camera wait, drop what the filter cannot keep up with.
    NewestFrameSource* newest = nullptr;
    if (source->isLive() && virtualCamera) {
        auto feed = std::make_unique<NewestFrameSource>(std::move(source), [] { return cli::stopRequested(); });
        newest = feed.get();
        source = std::move(feed);
    }
    if (!options.quiet)
        spdlog::info("{} -> {} on {}", source->describe(), options.output, filter->renderer());
    const int status = processClip(options, *source, demo, *sink, *filter, report);
    if (newest && !options.quiet)
        spdlog::info("live: {} frames captured, {} dropped (the filter was slower than the camera)",
                     newest->captured(), newest->dropped());
    return status;
}

/// The command line, bound to `o`.
void declareOptions(CLI::App& app, Options& o)
{
    // Given twice, an option's last value counts: a manifest line's options come after the
    // command line's and win (--batch).
    app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    cli::addVersionFlag(app, "defocus");
    app.add_option("input", o.input, "Colour input: TUM folder, image folder or image file");
    app.add_option("-o,--output", o.output,
                   "Output: DIR/ (numbered PNGs), FILE.mp4|.mkv|.avi (video), FILE.png (one frame), FILE.exr "
                   "(one frame, linear float)");
    app.add_option("--depth", o.depth, "Depth for INPUT: a folder (paired by sorted name) or one file");
    cli::addDepthScaleOption(app, o.depthScale);
    app.add_option("--focus", o.focus,
                   "Distance in focus, metres; 'inf' for infinity; 'auto' = median depth of the centre (or "
                   "--focus-point) of the first frame; 'track' = follow it frame by frame (the preview's "
                   "autofocus, --tau); keys such as 0s:1.2,2s:3.5 = a focus pull, eased in dioptres")
        ->capture_default_str();
    cli::addLensOptions(app, o.settings.lens, o, cli::FocalRange::Fixed);
    cli::addQualityOptions(app, o.settings.quality, o);
    std::vector<std::string> views;
    for (const Settings::View v : kViews)
        views.emplace_back(viewName(v));
    app.add_option("--view", o.view, "What to write: " + fmt::format("{}", fmt::join(views, ", ")))
        ->check(CLI::IsMember(views))
        ->capture_default_str();
    app.add_option("--contact-sheet", o.contactSheet, "Also write every view of one frame, labelled, to this PNG");
    app.add_option("--contact-frame", o.contactFrame, "Frame index for --contact-sheet")->capture_default_str();
    app.add_option("--frames", o.frames, "Stop after this many frames out")->check(cli::atLeast(1));
    app.add_option("--start", o.start, "Skip this many input frames first")->capture_default_str();
    app.add_option("--every", o.every, "Then take every Nth input frame (2 = every other)")
        ->check(cli::atLeast(1))
        ->capture_default_str();
    app.add_option("--focus-point", o.focusPoint,
                   "X,Y: measure the focus at this pixel (the median of the valid depths in a window around it) "
                   "instead of the centre; with --focus auto or track");
    app.add_option("--tau", o.autofocus.timeConstantS, "--focus track: time constant, seconds (critically damped), >= 0")
        ->check(cli::atLeast(0))
        ->capture_default_str();
    app.add_option("--fps", o.fps, "Frame rate of a video output, Hz [default: the input's]")->check(cli::positive());
    app.add_option("--timings", o.timings, "Write per-frame, per-pass timings with a p50/p95/max summary to this JSON file");
    app.add_flag("--explain", o.explain, "Print per frame which passes ran and on how many tiles");
    app.add_flag("--always-on", o.settings.quality.alwaysOn, "Run every pass on every pixel, ignoring the per-frame plan (for comparisons)");
    app.add_flag("--info", o.info, "Print the EGL/OpenGL platform, vendor, renderer and version, then exit");
    app.add_flag("--demo", o.demo,
                 "No INPUT: render a synthetic clip (60 frames, a focus pull; --frames sets its length) and blur "
                 "it; the lens options drive its camera too");
    app.add_option("--demo-scene", o.demoScene, "Scene for --demo: spheres or edges")
        ->check(CLI::IsMember(syntheticScenes()))
        ->capture_default_str();
    app.add_flag("-q,--quiet", o.quiet, "Only the summary line and errors");
    app.add_flag("-v,--verbose", o.verbose, "Debug logging");
    app.add_option("--progress-interval", o.progressInterval,
                   "Seconds between progress lines (frames, fps, time left) when standard error is not a terminal "
                   "(a log file, Slurm, CI; 0 = every frame); a terminal gets a bar redrawn in place")
        ->check(cli::atLeast(0))
        ->capture_default_str();

    cli::addCameraOptions(app, o.camera);
    app.add_flag("-y,--overwrite", o.overwrite,
                 "Replace outputs that exist (without it, an existing output is refused); --batch replaces the "
                 "output of each clip it runs (not done yet, or --redo) with or without it");
    app.add_flag("--keep-partial", o.keepPartial,
                 "When the run fails or is stopped (Ctrl-C, SIGTERM), keep the frames written so far as "
                 "OUTPUT.partial (out.partial.mp4, out.partial/); without it nothing is written to OUTPUT "
                 "then, and what it held before stays");
    app.add_option("--codec", o.codec,
                   "Video codec: h264 (default for .mp4), mp4v, ffv1 (lossless, default for .mkv), vp9 (default "
                   "for .webm), mjpg (default for .avi)")
        ->check(CLI::IsMember({"h264", "mp4v", "ffv1", "vp9", "mjpg"}));
    app.add_option("--image-format", o.imageFormat,
                   "Frames of a folder output: png (8-bit sRGB) or exr (linear float, HDR kept)")
        ->check(CLI::IsMember({"png", "exr"}))
        ->capture_default_str();
    app.add_option("--egl-device", o.eglDevice,
                   "EGL device to render on, only that one (--info lists them) [default: the GPU that "
                   "CUDA_VISIBLE_DEVICES makes CUDA's first, else the first that works, else Mesa surfaceless]")
        ->check(cli::atLeast(0));
    app.add_option("--report", o.report,
                   "When the clip is done (or failed on its input), write a JSON report: frames, settings, timings, "
                   "renderer, version, commit, exit status");
    app.add_option("--batch", o.batch,
                   "Many clips, one process: MANIFEST has one clip a line, INPUT<TAB>DEPTH<TAB>OUTPUT[<TAB>options] "
                   "or JSON; each clip gets OUTPUT.report.json; a rerun skips the clips done and tries the failed "
                   "ones again (README, Many clips)");
    app.add_option("--shard", o.shard,
                   "--batch: only clips k with k % N == I, as I/N [default: the Slurm array task's, else 0/1]");
    app.add_flag("--redo", o.redo, "--batch: do the clips done before again");
    app.add_option("--report-dir", o.reportDir, "--batch: put the reports here [default: beside each output]");
    app.add_option("--in-flight", o.inFlight, "--batch: clips processed at once, a GL context each, 1..16")
        ->check(cli::between(1, 16))
        ->capture_default_str();
    app.add_option("--read-threads", o.readThreads,
                   "Threads decoding a recorded clip ahead of the filter, 0..64; 0 = the CPUs this process may use "
                   "less one, shared by the --in-flight clips, at most 8")
        ->check(cli::between(0, 64))
        ->capture_default_str();
    app.add_option("--write-threads", o.writeThreads,
                   "Threads encoding the frames of a folder output (DIR/) side by side, 0..64; 0 = as "
                   "--read-threads' 0")
        ->check(cli::between(0, 64))
        ->capture_default_str();
}

/// --focus as metres: a number (all of the text) or 'inf'/'infinity'; nullopt otherwise.
std::optional<double> parseMetres(const std::string& text)
{
    if (text == "inf" || text == "infinity")
        return std::numeric_limits<double>::infinity();
    try {
        std::size_t used = 0;
        const double metres = std::stod(text, &used);
        if (used == text.size())
            return metres;
    } catch (const std::logic_error&) {
    }
    return std::nullopt;
}

/// After parsing: presets under the explicit options, names to enums, ranges. nullopt: go on;
/// otherwise the exit status (kExitUsage), with the reason logged.
std::optional<int> finishOptions(const CLI::App& app, Options& o)
{
    if (o.demo && !o.input.empty()) {
        spdlog::error("--demo renders its own input; drop INPUT '{}'", o.input);
        return kExitUsage;
    }
    if ((o.input.empty() && !o.demo) || o.output.empty()) {
        spdlog::error("INPUT and -o OUTPUT are required (see --help)");
        return kExitUsage;
    }
    cli::finishQuality(app, o, o.settings.quality);
    cli::finishLens(o, o.settings.lens);
    o.settings.view = viewNamed(o.view).value_or(Settings::View::Composite); // checked by CLI11
    try {
        std::optional<cv::Point2d> point;
        if (!o.focusPoint.empty())
            point = parsePoint(o.focusPoint);
        FocusControl check(o.focus, point, o.autofocus);
    } catch (const std::invalid_argument& error) {
        spdlog::error("{}", error.what());
        return kExitUsage;
    }
    // auto, track and keys are checked frame by frame; until then the focus is taken as at least
    // twice the focal length, so that only the other settings are checked here.
    const bool autoFocus = o.focus == "auto" || o.focus == "track" || FocusSchedule::isKeyed(o.focus);
    if (!autoFocus) {
        const std::optional<double> metres = parseMetres(o.focus);
        if (!metres) {
            spdlog::error("--focus '{}' is not metres, 'inf', 'auto', 'track' or keys", o.focus);
            return kExitUsage;
        }
        o.settings.lens.focusM = *metres;
    }
    Settings checked = o.settings;
    if (autoFocus)
        checked.lens.focusM = std::max(checked.lens.focusM, checked.lens.focalLengthMm * 2e-3);
    const auto issues = check(checked);
    for (const auto& issue : issues)
        spdlog::error("{}", issue);
    return issues.empty() ? std::nullopt : std::optional<int>(kExitUsage);
}

/// Options that --batch takes from its manifest, or that only --batch reads: refused where they
/// would be ignored. nullopt: go on; otherwise kExitUsage, with the reason logged.
std::optional<int> checkBatchOptions(const CLI::App& app, const Options& o)
{
    if (!o.batch.empty()) {
        const char* refused = !o.input.empty()      ? "INPUT"
                              : app.count("-o") > 0 ? "-o"
                              : app.count("--report") > 0 ? "--report"
                                                          : nullptr;
        if (!refused)
            return std::nullopt;
        spdlog::error("{} does not go with --batch: the manifest names each clip's input and output, and each clip's "
                      "report is OUTPUT.report.json (or in --report-dir)",
                      refused);
        return kExitUsage;
    }
    for (const char* name : {"--shard", "--redo", "--report-dir", "--in-flight"})
        if (app.count(name) > 0) {
            spdlog::error("{} is an option of --batch MANIFEST, which is not given", name);
            return kExitUsage;
        }
    return std::nullopt;
}

/// --egl-device N on a machine with fewer devices: a job that can never run here, so the command
/// line's status (2), not no-GL's retry (75). With no EGL device at all, the context's own error
/// (75) says why.
std::optional<int> checkEglDevice(const Options& o)
{
    if (!o.eglDevice)
        return std::nullopt;
    const std::vector<EglDevice> devices = eglDevices();
    if (devices.empty() ||
        std::any_of(devices.begin(), devices.end(), [&](const EglDevice& d) { return d.index == *o.eglDevice; }))
        return std::nullopt;
    std::vector<std::string> names;
    for (const EglDevice& d : devices)
        names.push_back(fmt::format("{} ({})", d.index, d.software ? "software" : "hardware"));
    spdlog::error("--egl-device {} does not exist here: this machine's EGL devices are {} (--info lists them)",
                  *o.eglDevice, fmt::join(names, ", "));
    return kExitUsage;
}

/// One clip with --report: the report is written after the clip, when it is done or failed on
/// its input; a stopped clip or a GL failure leaves none (as --batch does).
int runReported(const Options& options, std::optional<Filter>& filter)
{
    requireParentFolder(options.report, false); // before the clip, which would be lost for it
    nlohmann::json report = nlohmann::json::object();
    int status = kExitDone;
    try {
        status = runClip(options, filter, &report);
    } catch (const std::exception& error) {
        spdlog::error("{}", error.what());
        status = cli::statusFor(error);
        report["error"] = error.what();
    }
    if (status != kExitDone && status != kExitBadInput)
        return status;
    report["status"] = status == kExitDone ? "done" : "failed";
    report["exit_status"] = status;
    report["input"] = options.input;
    report["build"] = batch::buildInfo();
    batch::writeReport(options.report, report);
    return status;
}

/// --batch MANIFEST: this process's shard of the manifest's clips, each parsed as the command line
/// `arguments` followed by the clip's options, input, output and depth. Every clip's options are
/// checked before the first clip runs.
int runBatchCommand(const Options& global, const std::vector<std::string>& arguments)
{
    std::vector<batch::Clip> all;
    batch::Shard shard;
    try {
        all = batch::readManifest(global.batch);
        if (!global.shard.empty()) {
            const auto parsed = batch::parseShard(global.shard);
            if (!parsed) {
                spdlog::error("--shard '{}' is not I/N with 0 <= I < N", global.shard);
                return kExitUsage;
            }
            shard = *parsed;
        } else if (const auto slurm = batch::shardFromSlurm([](const char* name) { return std::getenv(name); })) {
            shard = *slurm;
        }
        batch::checkReportPaths(all, global.reportDir);
    } catch (const batch::ManifestError& error) {
        spdlog::error("{}", error.what());
        return kExitUsage;
    }
    const auto clipOptions = [&](const batch::Clip& clip, Options& o) -> std::optional<int> {
        std::vector<std::string> args = arguments;
        args.insert(args.end(), clip.options.begin(), clip.options.end());
        args.push_back(clip.input.string());
        args.push_back("--output=" + clip.output.string());
        if (!clip.depth.empty())
            args.push_back("--depth=" + clip.depth.string());
        CLI::App app;
        declareOptions(app, o);
        std::reverse(args.begin(), args.end()); // CLI11 takes a vector last argument first
        try {
            app.parse(args);
        } catch (const CLI::ParseError& error) {
            spdlog::error("{}:{}: {}", global.batch, clip.line, cli::errorMessage(error));
            return kExitUsage;
        }
        o.quiet = true;     // per-clip result lines only; no progress bars
        o.overwrite = true; // a clip without a report is the batch's to (re)write
        if (o.readThreads == 0)
            o.readThreads = ReadAheadSource::defaultThreads(global.inFlight); // the CPUs shared by the clips at once
        if (o.writeThreads == 0)
            o.writeThreads = ReadAheadSource::defaultThreads(global.inFlight);
        if (const auto status = finishOptions(app, o)) {
            spdlog::error("{}:{}: the clip's options are not valid (above)", global.batch, clip.line);
            return status;
        }
        return std::nullopt;
    };
    for (const auto& clip : all) {
        Options o;
        if (const auto status = clipOptions(clip, o))
            return *status;
    }
    batch::BatchOptions options;
    options.reportDir = global.reportDir;
    options.redo = global.redo;
    options.inFlight = global.inFlight;
    options.shard = shard;
    return batch::runBatch(
        batch::select(all, shard), options,
        [&](std::size_t) -> batch::ClipRunner {
            // One filter (a context and one shader build) for all of this worker's clips, made and
            // used on the worker's thread; each clip sets its settings and resets it.
            auto filter = std::make_shared<std::optional<Filter>>();
            filter->emplace(Settings{}, contextOptions(global));
            return [filter, &clipOptions](const batch::Clip& clip) {
                batch::ClipOutcome outcome;
                Options o;
                clipOptions(clip, o);
                try {
                    outcome.status = runClip(o, *filter, &outcome.report);
                } catch (const std::exception& error) {
                    spdlog::error("{}", error.what()); // once: runBatch names the clip after it
                    outcome.status = cli::statusFor(error);
                    outcome.report["error"] = error.what();
                }
                return outcome;
            };
        },
        cli::stopStatus);
}

} // namespace

int main(int argc, char** argv)
{
    Options o;
    CLI::App app{"defocus: depth of field with the bokeh of a real aperture (hexagonal by default) for RGB-D images and clips (McIntosh et al. 2012).\n"
                 "INPUT is a TUM RGB-D folder (rgb.txt + depth.txt), a folder of colour images (with --depth "
                 "FOLDER), one colour image (with --depth FILE), a video file (with --depth FILE, FOLDER or "
                 "depth.txt) or a V4L2 camera /dev/videoN (with --depth FILE or a Z16 camera); --demo needs none.\n"
                 "Exit status: 0 done, 1 bad input or output, 2 command line, 75 no GL or busy device (retry), "
                 "130 Ctrl-C, 143 SIGTERM."};
    declareOptions(app, o);
    if (const auto status = cli::parse(app, argc, argv))
        return *status;
    cli::logToStderr("defocus", o.quiet, o.verbose);

    try {
        if (const auto status = checkBatchOptions(app, o))
            return *status;
        if (const auto status = checkEglDevice(o))
            return *status;
        if (o.info)
            return printInfo(o);
        if (!o.batch.empty()) {
            cli::catchStopSignals();
            return runBatchCommand(o, std::vector<std::string>(argv + 1, argv + argc));
        }
        if (const auto status = finishOptions(app, o))
            return *status;
        cli::catchStopSignals();
        std::optional<Filter> filter;
        return o.report.empty() ? runClip(o, filter) : runReported(o, filter);
    } catch (const std::exception& error) {
        spdlog::error("{}", error.what());
        return cli::statusFor(error);
    }
}
