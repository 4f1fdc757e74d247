// SPDX-License-Identifier: LGPL-2.1-or-later
// libdefocus: the public API (include/defocus/) over the pipeline and its EGL context. The
// settings are turned into the pipeline's exactly as the defocus command line turns its flags.
#include "defocus/Filter.hpp"

#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "filter/ApiSettings.hpp"
#include "filter/Autofocus.hpp"
#include "filter/ColorSpace.hpp"
#include "filter/DepthPrep.hpp"
#include "filter/Pipeline.hpp"
#include "filter/Presets.hpp"
#include "filter/SceneAnalysis.hpp"
#include "filter/Settings.hpp"
#include "filter/Views.hpp"
#include "filter/gl/CallerContext.hpp"
#include "filter/gl/EglContext.hpp"
#include "filter/gl/Program.hpp"
#include "filter/gl/Renderer.hpp"

#ifndef DEFOCUS_VERSION
#error "DEFOCUS_VERSION is set by CMake from project(VERSION)"
#endif

namespace defocus {

namespace {

/// Seconds between frames when the timestamps do not say (the bundled clip's 30 Hz).
constexpr double kFallbackFrameS = 1.0 / 30.0;
/// The command line's `--focus auto`: median of the central 10 %, 2 m where it has no depth.
constexpr double kAutoWindow = 0.1;
constexpr float kAutoFallbackM = 2.0f;

template <typename T>
void checkRange(std::vector<std::string>& issues, const char* parameter, T& value, T low, T high, bool clamp)
{
    if (value >= low && value <= high)
        return;
    issues.push_back(fmt::format("{} must be between {} and {}, not {}", parameter, low, high, value));
    if (clamp)
        value = std::isnan(static_cast<double>(value)) ? low : std::clamp(value, low, high);
}

Encoding toEncoding(Settings::Output output)
{
    switch (output) {
    case Settings::Output::Srgb8: return Encoding::Srgb8;
    case Settings::Output::Linear32F: return Encoding::Linear32F;
    case Settings::Output::Srgb8Bgra: return Encoding::Srgb8Bgra;
    }
    return Encoding::Srgb8;
}

const char* describeType(const cv::Mat& image)
{
    switch (image.type()) {
    case CV_8UC1: return "8-bit, 1 channel";
    case CV_8UC3: return "8-bit, 3 channels";
    case CV_8UC4: return "8-bit, 4 channels";
    case CV_16UC1: return "16-bit, 1 channel";
    case CV_16UC3: return "16-bit, 3 channels";
    case CV_32FC1: return "float, 1 channel";
    case CV_32FC3: return "float, 3 channels";
    case CV_32FC4: return "float, 4 channels";
    default: return "of another type";
    }
}

} // namespace

std::vector<std::string> check(Settings& settings, bool clamp)
{
    // The lens and quality as the pipeline knows them, checked by the one validate() the
    // command line uses; an automatic focus is checked once it is measured (as `--focus auto`).
    LensSettings lens = toLens(settings.lens);
    const bool autoFocus = settings.autofocus.mode != AutofocusOptions::Mode::Off;
    const double givenFocus = lens.focusM;
    if (autoFocus && !(lens.focusM > lens.focalLengthMm * 1e-3))
        lens.focusM = lens.focalLengthMm * 2e-3;
    std::vector<std::string> issues;
    for (const auto& issue : validate(lens, clamp))
        issues.push_back(issue.message);
    if (autoFocus)
        lens.focusM = givenFocus;
    if (clamp)
        fromLens(lens, settings.lens);

    QualitySettings quality;
    quality.samples = settings.quality.samples.value_or(quality.samples);
    quality.highlightGain = settings.quality.highlightGain;
    for (const auto& issue : validate(quality, clamp))
        issues.push_back(issue.message);
    if (clamp) {
        if (settings.quality.samples)
            settings.quality.samples = quality.samples;
        settings.quality.highlightGain = quality.highlightGain;
    }

    checkRange(issues, "--autofocus-time-constant", settings.autofocus.timeConstantS, limits::kTimeConstantS[0],
               limits::kTimeConstantS[1], clamp);
    if (!(settings.depthScale >= limits::kDepthScale[0] && settings.depthScale <= limits::kDepthScale[1])) {
        issues.push_back(fmt::format("--depth-scale {} must be a positive number of units per metre", settings.depthScale));
        if (clamp)
            settings.depthScale = 1000.0;
    }
    return issues;
}

Quality resolve(const Quality& quality)
{
    return resolveQuality(quality);
}

std::vector<EglDevice> eglDevices()
{
    std::vector<EglDevice> out;
    for (const auto& d : gl::EglContext::devices())
        out.push_back({d.index, d.software, d.drmFile, d.cudaId});
    return out;
}

namespace {

RendererInfo toRendererInfo(const gl::ContextInfo& info)
{
    return {info.platform,
            info.device,
            info.eglVendor,
            info.eglVersion,
            info.glVendor,
            info.glRenderer,
            info.glVersion,
            info.timerQueries,
            gl::depthPrepOnGpu(info.glRenderer),
            gl::halfFloatTargets(info.glRenderer),
            gl::computePasses(info.glRenderer)};
}

gl::ContextOptions toContextOptions(const ContextOptions& options)
{
    gl::ContextOptions out;
    out.device = options.eglDevice;
    return out;
}

} // namespace

RendererInfo probeRenderer(const ContextOptions& context)
{
    try {
        return toRendererInfo(gl::EglContext::create(toContextOptions(context)).info());
    } catch (const gl::ContextError& error) {
        throw GlError(error.what());
    }
}

std::string_view viewName(Settings::View view)
{
    return viewName(toView(view));
}

std::optional<Settings::View> viewNamed(std::string_view name)
{
    return parseApiView(name);
}

std::string_view qualityName(Quality::Preset preset)
{
    return presetName(preset);
}

std::optional<Quality::Preset> qualityNamed(std::string_view name)
{
    return parsePreset(name);
}

void* eglDisplay(const ContextOptions& context)
{
    try {
        return gl::EglContext::keepDisplay(toContextOptions(context));
    } catch (const gl::ContextError& error) {
        throw GlError(error.what());
    }
}

std::string version()
{
    return DEFOCUS_VERSION;
}

struct Filter::Impl {
    std::optional<gl::EglContext> context; ///< none: the caller's (ContextOptions::callerContext)
    RendererInfo callerInfo;               ///< the caller's context, where it renders on that
    std::optional<Pipeline> pipeline; ///< destroyed first, with the context current
    Settings settings;
    LensSettings lens;
    QualitySettings quality;
    std::optional<Autofocus> follow;
    bool focusChosen = false; ///< FirstFrame: the first frame's focus is measured
    double firstFrameFocusM = 0.0;
    double previousTimestamp = 0.0;
    std::size_t frames = 0;
    FrameReport report;
    /// The last process()'s frame and lens, for contactSheet() to process it again.
    std::optional<Frame> lastFrame;
    std::optional<YuvImage> lastYuv; ///< its colour where it came as Y'CbCr
    double lastDepthUnits = 0.0; ///< its 16-bit depth's units a metre; 0: float metres
    LensSettings lastLens;
    /// submit()'s frames on their way back, oldest first, each with its report.
    struct InFlight {
        std::size_t index = 0; ///< the frame's number, for its report
        View view = View::Composite; ///< as the settings were at submit()
        Encoding encoding = Encoding::Srgb8;
        bool finished = false; ///< its passes run and its read queued (read, report)
        PendingRead read;
        FrameReport report;
    };
    std::deque<InFlight> inFlight;

    explicit Impl(std::optional<gl::EglContext> made) : context(std::move(made)) {}

    /// report from the pipeline's last frame, frame number `index`.
    void fillReport(std::size_t index) { fillReport(index, pipeline->timings(), report); }
    void fillReport(std::size_t index, const FrameTimings& t, FrameReport& r) const;
    /// The frame process(), submit() and processTextures() filter from the caller's images, and its lens (the
    /// autofocus stepped); throws InputError and SettingsError as process() documents. 16-bit
    /// depth stays as it came, its units a metre in `depthUnits` (0: the depth is float metres).
    /// `yuv`: the colour as Y'CbCr planes, `color` not used (the frame's colour left empty).
    Frame admit(const cv::Mat& color, const cv::Mat& depth, double timestampS, LensSettings& frameLens,
                double& depthUnits, const YuvImage* yuv = nullptr);
    /// admit() and the frame begun on the pipeline (whose context must be current): uploaded and
    /// measured; the frame and its lens kept for the report.
    void beginFrame(const cv::Mat& color, const cv::Mat& depth, double timestampS, const YuvImage* yuv = nullptr);
    /// beginFrame() and the frame finished: planned and its passes run (no frame in flight).
    void processFrame(const cv::Mat& color, const cv::Mat& depth, double timestampS);
    /// submit() without its check: the frame begun, the one submitted before finished and its
    /// read queued, the frame queued into inFlight.
    void submitFrame(const cv::Mat& color, const cv::Mat& depth, double timestampS, const YuvImage* yuv = nullptr);
    /// process(): with no frame in flight, submitFrame() then receiveFrame().
    cv::Mat processAlone(const cv::Mat& color, const cv::Mat& depth, double timestampS, const YuvImage* yuv);
    /// submit(): submitFrame() on a Filter with a context of its own.
    void submitOwnContext(const cv::Mat& color, const cv::Mat& depth, double timestampS, const YuvImage* yuv);
    /// receive() of a frame in flight (there must be one).
    cv::Mat receiveFrame();
    /// The pipeline's oldest begun frame (`entry`'s) planned and its passes run, its read queued.
    void finishFrame(InFlight& entry);
    /// The frames in flight dropped, in the pipeline too (the context must be current).
    void dropInFlight()
    {
        inFlight.clear();
        if (pipeline)
            pipeline->dropBegun();
    }

    /// The context current on the calling thread until the end of the call, whichever thread
    /// used the Filter before; then what was current there before is again. On the caller's
    /// context: its GL state is the passes' until the end of the call, then the caller's again.
    struct Call {
        gl::EglContext::Scope scope;
        std::optional<gl::CallerState> callerState;
    };
    Call current() const
    {
        if (!context)
            return {{}, std::optional<gl::CallerState>(std::in_place)};
        try {
            return {gl::EglContext::Scope(*context), std::nullopt};
        } catch (const gl::ContextError& error) {
            throw GlError(fmt::format("defocus::Filter: {} (a Filter is not thread-safe: one call at a time)",
                                      error.what()));
        }
    }

    /// Deletes the pipeline's GL objects with the context current.
    void dropPipeline() noexcept
    {
        try {
            const auto bound = current();
            dropInFlight();
            pipeline.reset();
        } catch (const Error&) {
            // Another thread is inside a call on this Filter (a caller's bug): the GL objects
            // go with the context.
        }
    }

    void apply(const Settings& next)
    {
        Settings checked = next;
        if (const auto issues = check(checked); !issues.empty())
            throw SettingsError(issues.front());
        const bool followChanged = !follow || next.autofocus.mode != settings.autofocus.mode ||
                                   next.autofocus.timeConstantS != settings.autofocus.timeConstantS;
        settings = next;
        lens = toLens(next.lens);
        quality = toQuality(next.quality);
        if (next.autofocus.mode != AutofocusOptions::Mode::Follow) {
            follow.reset();
        } else if (followChanged) {
            // A new time constant keeps the focus where it is and goes on from there.
            const double from = follow ? follow->focusM() : next.lens.focusM;
            AutofocusSettings afSettings;
            afSettings.timeConstantS = next.autofocus.timeConstantS;
            const bool measured = follow.has_value();
            follow.emplace(afSettings, std::isfinite(from) ? from : 1e6);
            if (measured)
                follow->setFocus(from);
        }
    }
};

Filter::Filter(const Settings& settings) : Filter(settings, ContextOptions{}) {}

Filter::Filter(const Settings& settings, const ContextOptions& context)
{
    Settings checked = settings;
    if (const auto issues = check(checked); !issues.empty())
        throw SettingsError(issues.front());
    try {
        if (context.callerContext) {
            impl_ = std::make_unique<Impl>(std::nullopt);
            impl_->callerInfo = toRendererInfo(gl::callerContextInfo());
            const auto bound = impl_->current();
            impl_->pipeline.emplace();
            impl_->apply(settings);
            return;
        }
        // create() makes the context current here: what was current before is put back.
        const gl::EglContext::Binding before = gl::EglContext::Binding::current();
        impl_ = std::make_unique<Impl>(gl::EglContext::create(toContextOptions(context)));
        const gl::EglContext::Scope bound(*impl_->context, before);
        impl_->pipeline.emplace();
    } catch (const gl::ContextError& error) {
        throw GlError(error.what());
    } catch (const gl::ShaderError& error) {
        throw GlError(error.what());
    }
    impl_->apply(settings);
}

Filter::~Filter()
{
    if (impl_)
        impl_->dropPipeline();
}

Filter::Filter(Filter&&) noexcept = default;

Filter& Filter::operator=(Filter&& other) noexcept
{
    if (this != &other) {
        if (impl_)
            impl_->dropPipeline();
        impl_ = std::move(other.impl_);
    }
    return *this;
}

void Filter::setSettings(const Settings& settings)
{
    impl_->apply(settings);
}

const Settings& Filter::settings() const
{
    return impl_->settings;
}

Frame Filter::Impl::admit(const cv::Mat& color, const cv::Mat& depth, double timestampS, LensSettings& frameLens,
                          double& depthUnits, const YuvImage* yuv)
{
    Impl& p = *this;
    Frame frame;
    if (yuv) {
        if (const std::string problem = yuvProblem(*yuv); !problem.empty())
            throw InputError(problem);
    } else if (color.empty()) {
        throw InputError("colour image is empty");
    } else switch (color.type()) {
    case CV_8UC3:
    case CV_8UC4: // BGRx: uploaded as it is, the fourth byte dropped on the way
    case CV_32FC3:
        // A view into a larger image (a cv::Rect of it) has gaps between its rows: the
        // pipeline uploads whole rows, so it gets a copy.
        frame.color = color.isContinuous() ? color : color.clone();
        break;
    default:
        throw InputError(fmt::format("colour image is {}; expected BGR 8-bit (CV_8UC3, or CV_8UC4 whose fourth "
                                     "channel is ignored) or float (CV_32FC3)",
                                     describeType(color)));
    }
    depthUnits = 0.0;
    if (!depth.empty()) {
        if (depth.type() == CV_16UC1) {
            // As it came: the pipeline converts it where it prepares the depth (on the GPU, after
            // an upload of half the bytes of float metres).
            frame.depth = depth;
            depthUnits = p.settings.depthScale;
        } else if (depth.type() == CV_32FC1) {
            frame.depth = depth; // read row by row: a view of a larger image needs no copy
        } else {
            throw InputError(fmt::format("depth image is {}; expected 16-bit single-channel (CV_16UC1, {} units per "
                                         "metre) or float metres (CV_32FC1)",
                                         describeType(depth), p.settings.depthScale));
        }
        if (const std::string problem = depthFitProblem(yuv ? yuv->y.size() : color.size(), "colour", depth.size(), "depth");
            !problem.empty())
            throw InputError(problem);
    }
    frame.index = p.frames;
    frame.timestampS = timestampS;
    frame.name = fmt::format("frame {}", p.frames);

    frameLens = p.lens;
    // The autofocus reads metres: 16-bit depth converted for it alone (0 stays 0: no measurement).
    cv::Mat converted;
    if (depthUnits > 0.0 && p.settings.autofocus.mode != AutofocusOptions::Mode::Off)
        depth.convertTo(converted, CV_32F, 1.0 / depthUnits);
    const cv::Mat& metres = depthUnits > 0.0 ? converted : frame.depth;
    switch (p.settings.autofocus.mode) {
    case AutofocusOptions::Mode::Off: break;
    case AutofocusOptions::Mode::FirstFrame:
        if (!p.focusChosen) {
            p.firstFrameFocusM = centreDepth(metres, kAutoWindow, kAutoFallbackM);
            LensSettings measured = frameLens;
            measured.focusM = p.firstFrameFocusM;
            if (const auto issues = validate(measured); !issues.empty())
                throw SettingsError(fmt::format("automatic focus: {}", issues.front().message));
            p.focusChosen = true;
        }
        frameLens.focusM = p.firstFrameFocusM;
        break;
    case AutofocusOptions::Mode::Follow: {
        const double dt = frameInterval(p.previousTimestamp, timestampS, kFallbackFrameS);
        frameLens.focusM = metres.empty() ? p.follow->advance(dt) : p.follow->update(metres, dt);
        // Nearer than the lens can focus: the nearest it can.
        frameLens.focusM = std::max(frameLens.focusM, frameLens.focalLengthMm * 1e-3 * 1.01);
        break;
    }
    }
    p.previousTimestamp = timestampS;
    return frame;
}

cv::Mat Filter::Impl::processAlone(const cv::Mat& color, const cv::Mat& depth, double timestampS,
                                    const YuvImage* yuv)
{
    if (!inFlight.empty())
        throw Error(fmt::format("defocus::Filter::process(): {} frames in flight; receive() them first",
                                inFlight.size()));
    submitFrame(color, depth, timestampS, yuv);
    return receiveFrame();
}

cv::Mat Filter::process(const cv::Mat& color, const cv::Mat& depth, double timestampS)
{
    return impl_->processAlone(color, depth, timestampS, nullptr);
}

cv::Mat Filter::process(const YuvImage& color, const cv::Mat& depth, double timestampS)
{
    return impl_->processAlone({}, depth, timestampS, &color);
}

namespace {

/// A Source's frame's colour is its planes where it has no BGR.
bool holdsYuv(const Frame& frame)
{
    return frame.color.empty() && !frame.yuv.y.empty();
}

/// 16-bit depth in other units than `unitsPerMetre` as metres; anything else as it is.
cv::Mat depthIn(const Frame& frame, double unitsPerMetre)
{
    const bool otherUnits = frame.depth.type() == CV_16UC1 && frame.depthScale > 0.0 && frame.depthScale != unitsPerMetre;
    return otherUnits ? depthMetres(frame) : frame.depth;
}

} // namespace

cv::Mat Filter::process(const Frame& frame)
{
    const cv::Mat depth = depthIn(frame, settings().depthScale);
    return holdsYuv(frame) ? process(frame.yuv, depth, frame.timestampS) : process(frame.color, depth, frame.timestampS);
}

cv::Mat yuvToBgr(const YuvImage& image)
{
    if (const std::string problem = yuvProblem(image); !problem.empty())
        throw InputError(problem);
    return convertYuv(image);
}

cv::Mat colorBgr(const Frame& frame)
{
    return holdsYuv(frame) ? yuvToBgr(frame.yuv) : frame.color;
}

void Filter::Impl::fillReport(std::size_t index, const FrameTimings& t, FrameReport& r) const
{
    const Impl& p = *this;
    r.index = index;
    r.focusM = p.lastLens.focusM;
    r.timings.totalMs = t.totalMs;
    r.timings.depthPrepMs = t.depthPrepMs;
    r.timings.analysisMs = t.analysisMs;
    r.timings.uploadMs = t.uploadMs;
    r.timings.renderMs = t.renderMs;
    r.timings.readbackMs = t.readbackMs;
    r.timings.gpu.clear();
    for (const auto& pass : t.gpu)
        r.timings.gpu.push_back({pass.name, pass.ms});
    r.timings.gpuFrame = t.gpuFrame;
    const FramePlan& plan = p.pipeline->plan();
    const SceneAnalysis& analysis = p.pipeline->analysis();
    r.plan.allInFocus = plan.allInFocus;
    r.plan.tiles = static_cast<std::size_t>(analysis.tiles.area());
    r.plan.blurTiles = plan.blurTiles.size();
    r.plan.copyTiles = plan.copyTiles.size();
    r.plan.holeFill = plan.holeFill;
    r.plan.invalidDepthFraction = p.pipeline->invalidDepthFraction();
    r.plan.nearField = plan.nearField;
    r.plan.highlightSprites = plan.highlightSprites;
    r.plan.tileSizePx = SceneAnalysis::kTileSize;
    r.plan.tileMap = cv::Mat::zeros(analysis.tiles, CV_8UC1);
    if (analysis.tileMinCoc.size() == analysis.tiles) // a frame with no depth has no CoC ranges
        for (int y = 0; y < analysis.tiles.height; ++y)
            for (int x = 0; x < analysis.tiles.width; ++x)
                r.plan.tileMap.at<std::uint8_t>(y, x) = analysis.tileNeedsBlur(x, y) ? 1 : 0;
    r.plan.explain = plan.explain(analysis);
}

const FrameReport& Filter::lastFrame() const
{
    return impl_->report;
}

std::vector<Timings::Pass> Filter::finishGpuTimings()
{
    const auto bound = impl_->current();
    std::vector<Timings::Pass> out;
    for (const auto& pass : impl_->pipeline->drainGpuTimes())
        out.push_back({pass.name, pass.ms});
    return out;
}

void Filter::Impl::beginFrame(const cv::Mat& color, const cv::Mat& depth, double timestampS, const YuvImage* yuv)
{
    LensSettings frameLens;
    double depthUnits = 0.0;
    Frame frame = admit(color, depth, timestampS, frameLens, depthUnits, yuv);
    pipeline->begin(frame, frameLens, quality, depthUnits, yuv);
    lastFrame = std::move(frame);
    lastYuv = yuv ? std::optional<YuvImage>(*yuv) : std::nullopt;
    lastDepthUnits = depthUnits;
    lastLens = frameLens;
}

void Filter::Impl::processFrame(const cv::Mat& color, const cv::Mat& depth, double timestampS)
{
    beginFrame(color, depth, timestampS);
    pipeline->finish();
}

void Filter::Impl::submitFrame(const cv::Mat& color, const cv::Mat& depth, double timestampS, const YuvImage* yuv)
{
    const auto bound = current();
    beginFrame(color, depth, timestampS, yuv);
    // The frame submitted before goes on now, behind this one's upload and measurement: the GPU
    // runs its passes while the CPU plans it, and measures this one meanwhile.
    for (InFlight& entry : inFlight)
        if (!entry.finished)
            finishFrame(entry);
    InFlight entry;
    entry.index = frames++;
    entry.view = toView(settings.view);
    entry.encoding = toEncoding(settings.output);
    inFlight.push_back(std::move(entry));
}

void Filter::Impl::finishFrame(InFlight& entry)
{
    pipeline->finish();
    entry.read = pipeline->readAsync(entry.view, entry.encoding);
    fillReport(entry.index, entry.read.timings(), entry.report);
    entry.finished = true;
}

cv::Mat Filter::Impl::receiveFrame()
{
    const auto bound = current();
    InFlight& oldest = inFlight.front();
    if (!oldest.finished)
        finishFrame(oldest);
    cv::Mat image = pipeline->collect(oldest.read);
    report = std::move(oldest.report);
    report.timings.readbackMs = oldest.read.timings().readbackMs;
    report.timings.totalMs = oldest.read.timings().totalMs;
    inFlight.pop_front();
    return image;
}

void Filter::Impl::submitOwnContext(const cv::Mat& color, const cv::Mat& depth, double timestampS,
                                    const YuvImage* yuv)
{
    if (!context)
        throw Error("defocus::Filter::submit(): frames in GL textures go through processTextures()");
    submitFrame(color, depth, timestampS, yuv);
}

void Filter::submit(const cv::Mat& color, const cv::Mat& depth, double timestampS)
{
    impl_->submitOwnContext(color, depth, timestampS, nullptr);
}

void Filter::submit(const YuvImage& color, const cv::Mat& depth, double timestampS)
{
    impl_->submitOwnContext({}, depth, timestampS, &color);
}

void Filter::submit(const Frame& frame)
{
    const cv::Mat depth = depthIn(frame, settings().depthScale);
    if (holdsYuv(frame))
        submit(frame.yuv, depth, frame.timestampS);
    else
        submit(frame.color, depth, frame.timestampS);
}

std::optional<cv::Mat> Filter::receive()
{
    if (impl_->inFlight.empty())
        return std::nullopt;
    return impl_->receiveFrame();
}

std::size_t Filter::framesInFlight() const
{
    return impl_->inFlight.size();
}

cv::Mat Filter::contactSheet()
{
    Impl& p = *impl_;
    if (!p.inFlight.empty())
        throw Error("defocus::Filter::contactSheet(): frames in flight; receive() them first");
    if (!p.lastFrame)
        throw InputError("contact sheet: no frame processed yet");
    const auto bound = p.current();
    Pipeline& pipeline = *p.pipeline;
    std::vector<std::pair<std::string, cv::Mat>> tiles;
    int number = 1;
    for (const View v : kAllViews)
        tiles.emplace_back(fmt::format("{} {}", number++, viewName(v)), pipeline.read(v, Encoding::Srgb8));
    tiles.emplace_back("plan: blur tiles outlined, copied dimmed, near field blue",
                       drawTileMap(tiles.front().second, pipeline.plan(), pipeline.analysis()));
    cv::Mat sheet = defocus::contactSheet(tiles);
    // Processed again so that the timings are a plain frame's, not the views' reads.
    const Encoding encoding = toEncoding(p.settings.output);
    pipeline.process(*p.lastFrame, p.lastLens, p.quality, p.lastDepthUnits, p.lastYuv ? &*p.lastYuv : nullptr);
    pipeline.read(toView(p.settings.view), encoding);
    p.fillReport(p.frames - 1);
    return sheet;
}

void Filter::reset()
{
    Impl& p = *impl_;
    if (!p.inFlight.empty()) {
        const auto bound = p.current();
        p.dropInFlight();
    }
    p.frames = 0;
    p.lastFrame.reset();
    p.focusChosen = false;
    p.previousTimestamp = 0.0;
    p.report = {};
    if (p.follow) {
        AutofocusSettings afSettings;
        afSettings.timeConstantS = p.settings.autofocus.timeConstantS;
        p.follow.emplace(afSettings, std::isfinite(p.settings.lens.focusM) ? p.settings.lens.focusM : 1e6);
    }
}

void Filter::release()
{
    // Every call puts back what was current on its thread before it, so the context is not
    // left bound anywhere; this unbinds it only where it still is (it never should be).
    if (impl_->context && impl_->context->isCurrent())
        impl_->context->release();
}

std::string Filter::renderer() const
{
    return rendererInfo().glRenderer;
}

RendererInfo Filter::rendererInfo() const
{
    return impl_->context ? toRendererInfo(impl_->context->info()) : impl_->callerInfo;
}

void Filter::processTextures(const GlFrame& frame, double timestampS)
{
    Impl& p = *impl_;
    if (p.context)
        throw InputError("processTextures: this Filter renders on a context of its own; make it with "
                         "ContextOptions::callerContext on the context that holds the textures");
    const auto bound = p.current();
    cv::Mat color, depth;
    try {
        const bool bgra = frame.colorOrder == GlFrame::Order::Bgra;
        const cv::Size size = gl::textureSize(frame.color, GL_RGBA8, "colour texture");
        if (size != cv::Size(frame.width, frame.height))
            throw InputError(fmt::format("colour texture {} is {}x{}, not the frame's {}x{}", frame.color, size.width,
                                         size.height, frame.width, frame.height));
        // BGRA bytes either way: the red channel is red (read as BGRA) or holds blue (as RGBA).
        color = gl::readTexture(frame.color, size, bgra ? GL_RGBA : GL_BGRA, GL_UNSIGNED_BYTE, CV_8UC4);
        if (gl::textureSize(frame.output, GL_RGBA8, "output texture") != size)
            throw InputError(fmt::format("output texture {} is not the colour's size", frame.output));
        if (frame.depth != 0)
            depth = gl::readDepthTexture(frame.depth, static_cast<gl::DepthTexture>(frame.depthFormat));
    } catch (const gl::ContextError& error) {
        throw InputError(error.what());
    }
    p.processFrame(color, depth, timestampS);
    // The result stays on the GPU, in the caller's texture.
    p.pipeline->readInto(toView(p.settings.view), frame.output, frame.outputOrder == GlFrame::Order::Bgra);
    p.fillReport(p.frames++);
}

} // namespace defocus
