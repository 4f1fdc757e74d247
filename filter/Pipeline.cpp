// SPDX-License-Identifier: LGPL-2.1-or-later
// Pipeline: runs the frame graph's nodes on pooled targets, reads results back, times everything.
#include "filter/Pipeline.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <deque>
#include <initializer_list>
#include <map>
#include <string_view>
#include <utility>

#include <epoxy/gl.h>
#include <opencv2/imgproc.hpp>

#include "filter/Aperture.hpp"
#include "filter/ColorSpace.hpp"
#include "filter/DepthPrep.hpp"
#include "filter/FrameGraph.hpp"
#include "filter/Lens.hpp"
#include "filter/Views.hpp"
#include "filter/gl/GpuTimer.hpp"
#include "filter/gl/Objects.hpp"
#include "filter/gl/Renderer.hpp"
#include "filter/gl/UploadRing.hpp"
#include "filter/passes/CocPass.hpp"
#include "filter/passes/CompositePass.hpp"
#include "filter/passes/CopyPass.hpp"
#include "filter/passes/DepthPrepPass.hpp"
#include "filter/passes/HexBlurPass.hpp"
#include "filter/passes/HighlightSpritePass.hpp"
#include "filter/passes/InFocusLightPass.hpp"
#include "filter/passes/RhombusBlurPass.hpp"
#include "filter/passes/SceneMeasurePass.hpp"
#include "filter/passes/NearBlurPass.hpp"
#include "filter/passes/OutputCopyPass.hpp"
#include "filter/passes/UpscalePass.hpp"
#include "filter/passes/ViewPass.hpp"
#include "filter/passes/YuvToRgbPass.hpp"

namespace defocus {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// A texture and the framebuffer that renders into it.
struct Target {
    gl::Texture texture;
    gl::Framebuffer framebuffer;
    /// Names the texture: a new number, unique in the process, each time it is (re)created, so
    /// that a framebuffer or view made of it elsewhere knows when it must be remade.
    unsigned generation = 0;

    void ensure(GLenum format, cv::Size size, const char* name)
    {
        if (texture && texture.format() == format && texture.width() == size.width &&
            texture.height() == size.height)
            return;
        framebuffer = {};
        texture = gl::Texture(format, size.width, size.height, name);
        framebuffer = gl::Framebuffer(texture, name);
        static unsigned textures = 0;
        generation = ++textures;
    }
};

/// The blur targets of the frame graph, keyed by format and size: a node's image takes a target
/// of its key that the frame holds no other image in, or a new one. A frame gives its targets
/// back when the next one is rendered; those the frame before did not take are deleted then (a
/// new size, or the other kernel's images).
class TargetPool {
public:
    Target& take(GLenum format, cv::Size size, std::string_view label)
    {
        for (auto& entry : entries_)
            if (!entry->held && entry->target.texture.format() == format &&
                entry->target.texture.width() == size.width && entry->target.texture.height() == size.height) {
                entry->held = true;
                glObjectLabel(GL_TEXTURE, entry->target.texture.id(), static_cast<GLsizei>(label.size()), label.data());
                return entry->target;
            }
        auto entry = std::make_unique<Entry>();
        entry->target.ensure(format, size, std::string(label).c_str());
        entry->held = true;
        entries_.push_back(std::move(entry));
        return entries_.back()->target;
    }
    /// A new frame: what the last one did not take goes; the rest is free again.
    void nextFrame()
    {
        std::erase_if(entries_, [](const std::unique_ptr<Entry>& entry) { return !entry->held; });
        for (auto& entry : entries_)
            entry->held = false;
        // A framebuffer of two targets lives as long as both do.
        std::erase_if(pairs_, [this](const auto& pair) { return !holds(pair.first.first) || !holds(pair.first.second); });
    }
    /// A framebuffer with `first` and `second` attached (draw buffers 0 and 1), kept while both live.
    const gl::Framebuffer& pair(const Target& first, const Target& second, std::string_view label)
    {
        gl::Framebuffer& framebuffer = pairs_[{first.generation, second.generation}];
        if (!framebuffer)
            framebuffer = gl::Framebuffer(first.texture, second.texture, label);
        return framebuffer;
    }
    std::size_t size() const { return entries_.size(); }

private:
    struct Entry {
        Target target;
        bool held = false;
    };
    bool holds(unsigned generation) const
    {
        return std::any_of(entries_.begin(), entries_.end(),
                           [&](const auto& entry) { return entry->target.generation == generation; });
    }
    std::vector<std::unique_ptr<Entry>> entries_; // stable addresses: nodes hold Target&
    std::map<std::pair<unsigned, unsigned>, gl::Framebuffer> pairs_;
};

/// Makes `texture` anew unless it has `format` and `size`; true when it did.
bool ensureTexture(gl::Texture& texture, GLenum format, cv::Size size, const char* name)
{
    if (texture && texture.format() == format && texture.width() == size.width && texture.height() == size.height)
        return false;
    texture = gl::Texture(format, size.width, size.height, name);
    return true;
}

/// GL_RENDERER of the current context, for the choices made from it (filter/gl/Renderer.hpp).
std::string_view rendererName()
{
    const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    return name ? name : "";
}

} // namespace

/// One frame from begin() until the one after it is begun: its images and settings, what they
/// derive, what the GPU holds of it (its own textures and measurement, so that the next frame
/// can go up and be measured before this one's passes run) and what the CPU found.
struct FrameContext {
    /// The frame's images, kept until its passes have run (they are skipped when all is in
    /// focus and the composite is all that is read). `color` is empty where the colour came as
    /// Y'CbCr planes (`yuv`) and has not been converted on the CPU.
    cv::Mat color, depthInput;
    YuvImage yuv;
    /// depthInput's units a metre where it is 16-bit (CV_16UC1); 0: float metres.
    double depthUnits = 0.0;
    cv::Size size;
    QualitySettings quality;
    /// The gather's CoC: the lens', scaled so that the rhombi's hexagon covers the aperture's
    /// area (gatherScale(); 1 for the hexagon). The sprites draw the aperture itself.
    CocCoefficients coefficients;
    /// The CoC parameters every pass of the frame binds: the lens' from begin() (the scene
    /// measurement), the plan's highlight gain and threshold added by render().
    CocParams cocParams{"frame coc params"};
    float maxCocPx = 0.0f;
    ApertureShape aperture;
    float bladeRotationDeg = 0.0f; ///< the gather's hexagon's
    float gatherScale = 1.0f;      ///< gatherScale(aperture): the gather's CoC over the lens'
    RhombusBlurPass::Directions directions{}; ///< the rhombi's: rotated and squeezed as the aperture is
    float fallbackDepth = 1.0f;
    std::size_t frameIndex = 0;
    /// The pipeline's number for the frame, counting begin()s: its GPU timer scopes go under it.
    std::uint64_t serial = 0;
    FrameTimings timings;
    /// The time spent on the frame: begin()'s, then from finish() on (a frame begun ahead waits
    /// between the two, which is not its time).
    Clock::time_point frameStart, finishStart;
    double beginMs = 0.0;
    double spentMs() const { return beginMs + msSince(finishStart); }

    gl::Texture colorTexture;
    gl::Texture colorBytes;   ///< 8-bit frames: colorTexture's bytes, undecoded (SceneMeasurePass)
    gl::Framebuffer colorBytesTarget; ///< colorBytes', for YuvToRgbPass
    /// Y'CbCr frames' planes as they came: Y', Cb (NV12: Cb and Cr), Cr; YUYV: its pairs alone.
    gl::Texture yuvPlanes[3];
    gl::Texture depthAsGiven; ///< the frame's depth as it came (prepareOnGpu)
    gl::Texture depth;        ///< filled, the frame's size
    gl::Framebuffer depthTarget; ///< `depth`'s (DepthPrepPass writes it)
    gl::StorageBuffer measurementBuffer; ///< SceneMeasurePass's
    gl::ReadbackBuffer measurementBack;  ///< the measurement on its way back, until read
    bool measuring = false;   ///< the GPU's measurement is submitted and not yet read
    bool hasDepth = false;    ///< the frame came with depth (the GPU's measurement counts its holes)
    SceneMeasurement measurement;

    /// The all-in-focus exit: decided from the valid depths' range before anything else, with
    /// the CoC of its two ends; depth prep then waits until a view needs it.
    bool inFocusExit = false;
    float exitMinCoc = 0.0f, exitMaxCoc = 0.0f;
    bool depthPrepared = false; ///< depth prep has run (or been submitted)
    /// The filled depth on the CPU: prepareDepth()'s, or read back from the GPU when asked for.
    PreparedDepth prepared;
    bool preparedOnCpu = false; ///< `prepared` holds this frame's filled depth
    /// The frame's share of depth without a measurement, from hole filling or, on the
    /// all-in-focus exit, from the look at the depth range that decided it.
    double invalidFraction = 0.0;
    float nearestDepth = 0.0f, farthestDepth = 0.0f; ///< the filled depth's range (the depth view)

    /// What finish() found and decided, and what of the frame graph has run: the analysis, the
    /// plan, whether the frame's nodes ran, which pooled target each image has (nullptr until a
    /// node writes it) and which images the nodes wrote.
    SceneAnalysis analysis;
    FramePlan plan;
    bool rendered = false;
    bool useTiles = false;         ///< the blurs draw the plan's blur tiles and copy the rest
    bool upscaleUsesTiles = false; ///< the upscale puts detail back on the plan's tiles only
    std::array<Target*, kImageCount> images{};
    std::vector<bool> written = std::vector<bool>(kImageCount, false);
};

struct Pipeline::Impl {
    gl::VertexArray vao = gl::VertexArray::create();
    /// The frames' pixels on their way up where the GPU prepares depth: 2 uploads a frame, for
    /// up to 3 frames queued.
    gl::UploadRing uploads{6, "upload ring"};
    DepthPrepPass depthPrepPass;
    SceneMeasurePass sceneMeasurePass;
    CocPass cocPass;
    HighlightSpritePass highlightSpritePass;
    InFocusLightPass inFocusLightPass;
    HexBlurPass hexBlurPass;
    RhombusBlurPass rhombusBlurPass;
    CompositePass compositePass;
    CopyPass copyPass;
    YuvToRgbPass yuvToRgbPass;
    NearBlurPass nearBlurPass;
    UpscalePass upscalePass;
    ViewPass viewPass;
    OutputCopyPass outputCopyPass;
    TileList blurTiles, copyTiles, nearTiles;
    TileList detailTiles; ///< Resolution::Half: where the upscale puts the frame's detail back
    TileList highlightTiles; ///< where the CoC pass treats highlights pixel by pixel
    TileList frameHighlightTiles; ///< the same tiles in the frame's pixels (InFocusLightPass)
    gl::StorageBuffer neighbourhoods; ///< SceneAnalysis::tileNeighbourhood, for the bokeh sprites
    gl::GpuTimer timer;

    /// The blur targets (FrameGraph's pooled images); the frame context says which it holds.
    TargetPool pool;
    Target outSrgb, outLinear;
    float viewLow = 0.0f, viewHigh = 0.0f; ///< the last depth or CoC view's legend
    gl::Texture nearDiameter;            ///< per tile, R32F

    /// The frame the passes, the reads and the accessors are of: the one finish() took last.
    FrameContext current;
    /// Frames begin() took that finish() has not, oldest first.
    std::deque<FrameContext> staged;
    /// Contexts of frames done with, for the next begin() to reuse their textures and buffers.
    std::vector<FrameContext> spareContexts;
    cv::Size size;     ///< current's
    cv::Size blurSize; ///< the blur passes': the frame's, or half or a quarter of it (Resolution::Half)
    int blurShift = 0; ///< log2 of size / blurSize (the plan's FramePlan::blurShift)
    /// Depth prep and the scene measurement on the GPU (DepthPrepPass, SceneMeasurePass), or
    /// on the CPU (prepareDepth(), measureScene()) with the filled depth uploaded
    /// (gl::depthPrepOnGpu()).
    bool prepareOnGpu = gl::depthPrepOnGpu(rendererName());
    /// TargetFormat::Auto: half floats here (gl::halfFloatTargets()).
    const bool halfFloatTargets = gl::halfFloatTargets(rendererName());
    DepthPrepWorkspace depthWorkspace; // prepareDepth()'s buffers, kept from frame to frame
    cv::Mat depthMetres; // 16-bit depth in metres for prepareDepth(), kept from frame to frame
    /// Readback buffers collected and free again, for the next reads of their size.
    std::vector<gl::ReadbackBuffer> spareReadbacks;
    /// A spare readback buffer of at least `bytes` (those too small are dropped), or a new one.
    gl::ReadbackBuffer takeReadbackBuffer(GLsizeiptr bytes)
    {
        while (!spareReadbacks.empty()) {
            gl::ReadbackBuffer spare = std::move(spareReadbacks.back());
            spareReadbacks.pop_back();
            if (spare.size() >= bytes)
                return spare;
        }
        return gl::ReadbackBuffer(bytes, "readback");
    }

    /// The images collect() returned lately. One whose caller has let go of it (this holds the
    /// only reference) is filled again: a new frame-sized allocation is fresh pages from the
    /// kernel, which the copy into it faults in one by one (~60 % on top of the copy).
    std::vector<cv::Mat> outputs;
    static constexpr std::size_t kOutputsKept = 3;
    cv::Mat takeOutput(cv::Size imageSize, int type)
    {
        for (const cv::Mat& kept : outputs)
            if (kept.size() == imageSize && kept.type() == type && CV_XADD(&kept.u->refcount, 0) == 1)
                return kept;
        if (outputs.size() == kOutputsKept)
            outputs.erase(outputs.begin());
        return outputs.emplace_back(imageSize, type);
    }

    std::size_t gpuFrameIndex = 0; ///< frame whose GPU scopes are pending in the timer
    std::uint64_t serials = 0;     ///< frames begun

    /// Whether the blur passes draw or run as compute shaders (Pipeline::computePasses()).
    void setStage(ShaderStage stage)
    {
        for (ShadedPass* pass : std::initializer_list<ShadedPass*>{&cocPass, &rhombusBlurPass, &hexBlurPass, &compositePass,
                                                                   &copyPass, &nearBlurPass, &upscalePass, &depthPrepPass})
            pass->setStage(stage);
    }
    /// The frame's nodes (FrameGraph: frameNodes()), once a frame.
    void render();
    /// `view` of the last frame rendered into `out` (not for a frame all in focus): the view's
    /// nodes; `caller`: copied on into a caller's texture. read() and readInto() without the read.
    void renderView(View view, const Target& out, const gl::Framebuffer* caller = nullptr, bool bgra = false);
    /// The output target of `encoding`, of the frame's size.
    Target& output(Encoding encoding);
    /// The plan's choices, which pick the graph's nodes.
    GraphChoices choices() const
    {
        return {current.quality.kernel, blurShift != 0, current.plan.nearField, current.plan.highlightSprites};
    }
    /// The frame's read-back time from `readStart`, its total, and the GPU times it collected.
    void finishTimings(Clock::time_point readStart);
    /// Runs `node`; Image::Output is `out`, Image::CallerTexture `caller`.
    void run(const Node& node, const Target* out, const gl::Framebuffer* caller, bool bgra);
    /// The target of a pooled image, taken from the pool when a node first writes it this frame.
    Target& image(Image which);
    /// The framebuffer a node draws into: its one image's, or its two images' together.
    const gl::Framebuffer& drawTarget(const Node& node, const Target* out);
    /// The frame's texture of an image a node reads.
    const gl::Texture& texture(Image which, const Target* out);
    void uploadNearDiameter();
    /// `f`'s filled depth texture (and its framebuffer) of the frame's size.
    static void ensureDepth(FrameContext& f)
    {
        if (ensureTexture(f.depth, GL_R32F, f.size, "filled depth"))
            f.depthTarget = gl::Framebuffer(f.depth, "filled depth");
    }
    /// `f`'s colour into its colorTexture (and its bytes' view), through `ring` or straight: BGR
    /// or float as it is; Y'CbCr planes as they are, into yuvPlanes (the yuv-to-rgb node converts
    /// them).
    void uploadColor(FrameContext& f, gl::UploadRing* ring)
    {
        const bool srgbInput = f.color.depth() == CV_8U; // an empty Mat's too: Y'CbCr
        if (ensureTexture(f.colorTexture, srgbInput ? GL_SRGB8 : GL_RGB32F, f.size, "input colour")) {
            f.colorBytes =
                srgbInput ? gl::Texture::view(f.colorTexture, GL_RGB8, "input colour, bytes") : gl::Texture();
            f.colorBytesTarget = gl::Framebuffer();
        }
        const auto up = [&](gl::Texture& texture, GLenum format, GLenum type, const cv::Mat& image) {
            if (ring)
                ring->upload(texture, format, type, image.data, image.total() * image.elemSize());
            else
                texture.upload(format, type, image.data);
        };
        if (!f.color.empty()) {
            // BGRx goes up as it is: the texture has no alpha, so the fourth byte is dropped on the way.
            up(f.colorTexture, f.color.channels() == 4 ? GL_BGRA : GL_BGR, srgbInput ? GL_UNSIGNED_BYTE : GL_FLOAT,
               f.color);
            return;
        }
        const cv::Mat* planes[3] = {&f.yuv.y, &f.yuv.u, &f.yuv.v};
        static const char* const kNames[3] = {"Y' plane", "Cb plane", "Cr plane"};
        for (int i = 0; i < yuvPlaneCount(f.yuv.layout); ++i) {
            const bool pair = planes[i]->channels() == 2;
            ensureTexture(f.yuvPlanes[i], pair ? GL_RG8UI : GL_R8UI, planes[i]->size(), kNames[i]);
            // Planes go up whole rows at a time: a view with padded rows, copied here (the CPU's
            // conversion reads it as it is).
            up(f.yuvPlanes[i], pair ? GL_RG_INTEGER : GL_RED_INTEGER, GL_UNSIGNED_BYTE,
               planes[i]->isContinuous() ? *planes[i] : planes[i]->clone());
        }
        if (!f.colorBytesTarget)
            f.colorBytesTarget = gl::Framebuffer(f.colorBytes, "input colour, bytes");
    }
    /// begin()'s work on `f`: the frame, its settings, the all-in-focus exit or depth prep.
    void begin(FrameContext& f, const Frame& frame, const LensSettings& lens, const QualitySettings& quality,
               double depthUnitsPerMetre, const YuvImage* yuv);
    /// Depth prep and the scene measurement of `f`: on the GPU, the frame's images uploaded and
    /// the measurement submitted (read by plan()); on the CPU, both done and the filled depth uploaded.
    void prepare(FrameContext& f);
    /// The current frame's measurement (waiting for the GPU's), analysis and plan.
    void planFrame();
    void setBlurShift(int shift)
    {
        blurShift = shift;
        const int round = (1 << shift) - 1;
        blurSize = {(size.width + round) >> shift, (size.height + round) >> shift};
    }
    /// The analysis' tiles in the blur passes' pixels.
    int tileSize() const { return SceneAnalysis::kTileSize >> blurShift; }
    explicit Impl(bool timers) : timer(timers) {}
};

Pipeline::Pipeline(bool timers)
{
    GLint bits = 0;
    glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
    impl_ = std::make_unique<Impl>(timers && bits > 0);
    impl_->setStage(gl::computePasses(rendererName()) ? ShaderStage::Compute : ShaderStage::Fragment);
    // Only sRGB-format attachments are affected: those get linear -> sRGB encoding on write.
    glEnable(GL_FRAMEBUFFER_SRGB);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);

    // Warm-up: drivers compile shaders on first draw (llvmpipe JITs them) and llvmpipe reports
    // garbage for the first timer queries of a context; pay both here, not on a user's frame 0.
    cv::Mat color(32, 32, CV_8UC3, cv::Scalar::all(128)), depth(32, 32, CV_32F, cv::Scalar(4.0f));
    depth(cv::Rect(0, 0, 16, 16)).setTo(1.0f);
    LensSettings lens;
    lens.focusM = 1.0;
    QualitySettings quality;
    for (const View view : {View::Composite, View::Input}) {
        run({color, depth, 0.0, 0, "warm-up"}, lens, quality, view, Encoding::Srgb8);
        run({color, depth, 0.0, 0, "warm-up"}, lens, quality, view, Encoding::Linear32F);
    }
    quality.resolution = Resolution::Half;
    run({color, depth, 0.0, 0, "warm-up"}, lens, quality, View::Composite, Encoding::Srgb8);
    drainGpuTimes();
    impl_->current.timings = {};
}

Pipeline::~Pipeline() = default;

void Pipeline::process(const Frame& frame, const LensSettings& lens, const QualitySettings& quality,
                       double depthUnitsPerMetre, const YuvImage* yuv)
{
    CV_Assert(impl_->staged.empty());
    begin(frame, lens, quality, depthUnitsPerMetre, yuv);
    finish();
}

void Pipeline::begin(const Frame& frame, const LensSettings& lens, const QualitySettings& quality,
                     double depthUnitsPerMetre, const YuvImage* yuv)
{
    Impl& p = *impl_;
    CV_Assert(yuv ? frame.color.empty() && yuvProblem(*yuv).empty()
                  : !frame.color.empty() && (frame.color.type() == CV_8UC3 || frame.color.type() == CV_8UC4 ||
                                             frame.color.type() == CV_32FC3));
    FrameContext f;
    if (!p.spareContexts.empty()) {
        f = std::move(p.spareContexts.back());
        p.spareContexts.pop_back();
    }
    p.begin(f, frame, lens, quality, depthUnitsPerMetre, yuv);
    f.beginMs = msSince(f.frameStart);
    p.staged.push_back(std::move(f));
}

std::size_t Pipeline::begun() const
{
    return impl_->staged.size();
}

void Pipeline::dropBegun()
{
    Impl& p = *impl_;
    for (FrameContext& f : p.staged) {
        p.timer.forget(f.serial);
        p.spareContexts.push_back(std::move(f));
    }
    p.staged.clear();
}

void Pipeline::Impl::begin(FrameContext& f, const Frame& frame, const LensSettings& lens,
                           const QualitySettings& quality, double depthUnitsPerMetre, const YuvImage* yuv)
{
    f.timings = {};
    f.frameStart = Clock::now();
    f.size = yuv ? yuv->y.size() : frame.color.size();
    f.color = frame.color;
    f.yuv = yuv ? *yuv : YuvImage{};
    f.depthInput = frame.depth;
    f.depthUnits = depthUnitsPerMetre;
    CV_Assert(f.depthInput.empty() || f.depthInput.type() == (f.depthUnits > 0.0 ? CV_16UC1 : CV_32FC1));
    f.quality = quality;
    if (f.quality.targetFormat == TargetFormat::Auto)
        f.quality.targetFormat = halfFloatTargets ? TargetFormat::Rgba16F : TargetFormat::Rgba32F;
    f.aperture = ApertureShape::of(lens);
    // The gather's hexagon: the lens' for a hexagonal aperture; for other shapes a corner on top,
    // whose lines lie on the axes (a rotated hexagon's off-axis lines cost llvmpipe 8x as much).
    f.bladeRotationDeg = f.aperture.isHexagon() ? static_cast<float>(lens.bladeRotationDeg) : 0.0f;
    const GatherSqueeze squeeze = gatherSqueeze(f.aperture);
    f.directions = RhombusBlurPass::directions(f.bladeRotationDeg, squeeze.x, squeeze.y);
    const CocCoefficients lensCoc = cocCoefficients(lens, f.size.width);
    f.gatherScale = gatherScale(f.aperture);
    f.coefficients = scaled(lensCoc, f.gatherScale);
    f.maxCocPx = lensCoc.maxCocPx;
    f.frameIndex = frame.index;
    f.serial = ++serials;
    f.fallbackDepth = std::isinf(lens.focusM) ? 1e6f : static_cast<float>(lens.focusM);
    f.depthPrepared = false;
    f.preparedOnCpu = false;
    f.measuring = false;
    f.inFocusExit = false;

    // All in focus? Hole filling only averages valid depths, so the valid range bounds the
    // filled map, and CoC is monotonic in depth: the CoC of the two ends decides, before any
    // hole filling, analysis or upload. The lens' CoC: a lens that blurs nothing by half a pixel
    // passes the frame through whatever the gather's scale.
    if (quality.adaptive) {
        const auto start = Clock::now();
        float lo = f.fallbackDepth, hi = f.fallbackDepth;
        f.invalidFraction = validDepthRange(frame.depth, f.depthUnits > 0.0 ? f.depthUnits : 1.0, lo, hi);
        const float c0 = cocPixels(lensCoc, lo), c1 = cocPixels(lensCoc, hi);
        f.timings.analysisMs = msSince(start);
        if (std::max(std::abs(c0), std::abs(c1)) < 0.5f) {
            f.inFocusExit = true;
            f.exitMinCoc = std::min(c0, c1);
            f.exitMaxCoc = std::max(c0, c1);
            return;
        }
    }
    prepare(f);
}

void Pipeline::finish()
{
    Impl& p = *impl_;
    CV_Assert(!p.staged.empty());
    p.spareContexts.push_back(std::exchange(p.current, std::move(p.staged.front())));
    p.staged.pop_front();
    FrameContext& f = p.current;
    f.finishStart = Clock::now();
    p.size = f.size;
    p.setBlurShift(f.quality.resolution == Resolution::Half ? 1 : 0);
    p.current.rendered = false;
    p.current.plan = {};
    p.current.analysis = {};
    if (f.inFocusExit) {
        p.current.analysis.minCoc = f.exitMinCoc;
        p.current.analysis.maxCoc = f.exitMaxCoc;
        p.current.plan.allInFocus = true;
        return;
    }
    const auto start = Clock::now();
    p.planFrame();
    f.timings.analysisMs += msSince(start);
    if (!(f.quality.adaptive && p.current.plan.allInFocus))
        p.render();
}

void Pipeline::Impl::prepare(FrameContext& f)
{
    // Depth: colour-sized, holes filled. With no depth at all, everything sits on the focus plane.
    // The rhombi's bokeh sprites take the light above white out of the gather; its edges go with
    // it (float frames only: 8-bit ones have nothing above white).
    const bool lightEdges =
        f.color.type() == CV_32FC3 && f.quality.kernel == HexagonKernel::RhombiSum && f.quality.highlightSprites;
    // Y'CbCr where the CPU prepares depth: BGR here, for the measurement and the upload (the
    // colour's way to the GPU: upload time).
    double convertMs = 0.0;
    if (!prepareOnGpu && f.color.empty()) {
        const auto converting = Clock::now();
        f.color = convertYuv(f.yuv);
        convertMs = msSince(converting);
    }
    auto start = Clock::now();
    const bool srgbInput = f.color.depth() == CV_8U; // Y'CbCr too
    CV_Assert(f.color.empty() || f.color.isContinuous());
    const bool units = f.depthUnits > 0.0; // 16-bit depth
    if (prepareOnGpu) {
        // The frame's pixels go up as they came; only the measurement comes back, read when the
        // frame is planned (planFrame()), by when the GPU has long made it when a frame is in
        // flight before it.
        uploadColor(f, &uploads);
        ensureDepth(f);
        f.hasDepth = !f.depthInput.empty();
        const cv::Mat given = f.depthInput.isContinuous() ? f.depthInput : f.depthInput.clone();
        if (f.hasDepth) {
            ensureTexture(f.depthAsGiven, units ? GL_R16UI : GL_R32F, given.size(), "depth as given");
            uploads.upload(f.depthAsGiven, units ? GL_RED_INTEGER : GL_RED, units ? GL_UNSIGNED_SHORT : GL_FLOAT,
                           given.data, given.total() * given.elemSize());
        }
        f.timings.uploadMs = msSince(start);
        start = Clock::now();
        glBindVertexArray(vao.id());
        for (const Node& node : prepareNodes(true, lightEdges, f.color.empty())) {
            timer.begin(node.name, f.serial);
            switch (node.pass) {
            case PassKind::YuvToRgb:
                yuvToRgbPass.run(f.yuv.layout, f.yuvPlanes, f.yuv.matrix, f.yuv.range, f.colorBytesTarget);
                break;
            case PassKind::DepthPrep:
                depthPrepPass.run(f.hasDepth ? &f.depthAsGiven : nullptr, f.depthUnits, f.fallbackDepth,
                                  lightEdges ? &f.colorTexture : nullptr, f.depth, f.depthTarget);
                break;
            case PassKind::SceneMeasure:
                f.cocParams.set(f.coefficients, f.quality.targetFormat == TargetFormat::Rgba16F);
                sceneMeasurePass.run(f.depth, srgbInput ? f.colorBytes : f.colorTexture, srgbInput, f.cocParams,
                                     f.hasDepth ? &depthPrepPass.measured() : nullptr, f.measurementBuffer,
                                     f.measurementBack);
                break;
            default: CV_Error(cv::Error::StsInternal, std::string(node.name) + " is not a pass that prepares a frame");
            }
            timer.end();
        }
        f.timings.depthPrepMs = msSince(start);
        f.measuring = true;
    } else {
        // 16-bit depth in metres first, as a 16-bit depth file is read (0 stays 0: no measurement).
        if (units)
            f.depthInput.convertTo(depthMetres, CV_32F, 1.0 / f.depthUnits);
        prepareDepth(units ? depthMetres : f.depthInput, f.size, f.fallbackDepth, depthWorkspace, f.prepared);
        if (lightEdges)
            putLightEdgesAtTheirLightsDepth(f.color, f.prepared.metres);
        f.timings.depthPrepMs = msSince(start);
        f.invalidFraction = f.prepared.invalidFraction;
        f.preparedOnCpu = true;

        start = Clock::now();
        ensureDepth(f);
        // Straight: on a software renderer a ring's copy would come on top of the driver's own.
        uploadColor(f, nullptr);
        CV_Assert(f.prepared.metres.isContinuous());
        f.depth.upload(GL_RED, GL_FLOAT, f.prepared.metres.data);
        f.timings.uploadMs = convertMs + msSince(start);
        start = Clock::now();
        f.measurement = measureScene(f.prepared.metres, f.color, f.coefficients);
        f.timings.analysisMs += msSince(start);
    }
    f.depthPrepared = true;
}

void Pipeline::Impl::planFrame()
{
    FrameContext& f = current;
    if (!f.depthPrepared)
        prepare(f);
    if (f.measuring) {
        std::size_t invalidPixels = 0;
        f.measurement = SceneMeasurePass::read(f.measurementBack, f.size, f.hasDepth, invalidPixels);
        f.invalidFraction = static_cast<double>(invalidPixels) / static_cast<double>(f.size.area());
        f.measuring = false;
    }
    double lo = 0.0, hi = 0.0;
    cv::minMaxLoc(f.measurement.tileMinDepth, &lo);
    cv::minMaxLoc(f.measurement.tileMaxDepth, nullptr, &hi);
    f.nearestDepth = static_cast<float>(lo);
    f.farthestDepth = static_cast<float>(hi);
    f.analysis = finishAnalysis(f.measurement, f.coefficients, f.invalidFraction);
    const bool allInFocus = f.plan.allInFocus && f.quality.adaptive;
    // Highlights to treat: the plan's (FramePlan::highlights) on a frame not all in focus, which
    // makePlan() derives from the analysis alone, whatever size it picks.
    const bool lights = f.analysis.hasHighlights() && !f.analysis.allInFocus();
    const bool eightBit = f.color.depth() == CV_8U;
    const double highlightGain = eightBit && lights ? f.quality.highlightGain : 1.0;
    // Sprites where a blurred pixel can be brighter than white: float input's highlights, or
    // 8-bit ones scaled up by the gain; and only where such pixels are few, lights rather than
    // bright surfaces (HighlightSpritePass::kMostHighlightPixels).
    const bool sprites = f.quality.highlightSprites && f.quality.kernel == HexagonKernel::RhombiSum && lights &&
                         (!eightBit || highlightGain > 1.0) &&
                         f.analysis.highlightFraction <= HighlightSpritePass::kMostHighlightPixels;
    // Quarter size only on frames without bokeh sprites: the rims of the lights' hexagons, which
    // the gather draws up to white, came out 4 px soft at quarter size (the corpus enlarged 3x,
    // `defocus-bench accuracy --scale 3`: 0.38 dB less in the median, most of it in the lights'
    // zone; docs/benchmarks.md).
    f.plan = makePlan(f.analysis, f.quality.nearField, f.quality.kernel, f.quality.resolution, f.quality.samples,
                    f.quality.quarterOnLargeBlur && !sprites);
    setBlurShift(f.plan.blurShift);
    f.plan.highlightGain = highlightGain;
    f.plan.highlightSprites = sprites;
    f.plan.gatherScale = f.gatherScale;
    f.plan.allInFocus = f.plan.allInFocus || allInFocus;
}

void Pipeline::Impl::uploadNearDiameter()
{
    ensureTexture(nearDiameter, GL_R32F, current.analysis.tiles, "near diameter per tile");
    CV_Assert(current.analysis.tileNearDiameter.isContinuous());
    if (blurShift == 0) {
        nearDiameter.upload(GL_RED, GL_FLOAT, current.analysis.tileNearDiameter.data);
    } else {
        // The analysis measured the frame's pixels; the blur counts half-size ones.
        const cv::Mat scaled = current.analysis.tileNearDiameter * (1.0 / (1 << blurShift));
        nearDiameter.upload(GL_RED, GL_FLOAT, scaled.data);
    }
}

Target& Pipeline::Impl::image(Image which)
{
    Target*& held = current.images[static_cast<std::size_t>(which)];
    if (!held) {
        const ImageInfo& info = imageInfo(which);
        CV_Assert(info.pooled() && info.scale == ImageScale::Blur);
        held = &pool.take(current.quality.targetFormat == TargetFormat::Rgba16F ? GL_RGBA16F : GL_RGBA32F, blurSize,
                          info.name);
    }
    return *held;
}

const gl::Texture& Pipeline::Impl::texture(Image which, const Target* out)
{
    switch (which) {
    case Image::Color: return current.colorTexture;
    case Image::Depth: return current.depth;
    case Image::NearDiameter: return nearDiameter;
    case Image::Output: return out->texture;
    default: break;
    }
    assert(current.written[static_cast<std::size_t>(which)]);
    return image(which).texture;
}

const gl::Framebuffer& Pipeline::Impl::drawTarget(const Node& node, const Target* out)
{
    // The images drawn into: the pool's and the output, not a buffer a node fills beside them
    // (the CoC pass's sprites, which their search writes).
    std::array<Image, 2> drawn{};
    std::size_t count = 0;
    for (const Image which : node.writes)
        if (imageInfo(which).pooled() || which == Image::Output) {
            CV_Assert(count < drawn.size());
            drawn[count++] = which;
        }
    CV_Assert(count > 0);
    if (count == 1)
        return drawn[0] == Image::Output ? out->framebuffer : image(drawn[0]).framebuffer;
    return pool.pair(image(drawn[0]), image(drawn[1]), node.name);
}

void Pipeline::Impl::run(const Node& node, const Target* out, const gl::Framebuffer* caller, bool bgra)
{
    FrameContext& f = current;
    const int samples = f.quality.samples;
    const gl::Texture* near = f.plan.nearField ? &nearDiameter : nullptr;
    const TileList* tiles = f.useTiles ? &blurTiles : nullptr;
    // McIntosh et al.'s first pass runs along an edge of the hexagon. Edges and corners point
    // the same ways (mod 60 deg), so the edge nearest an axis is the rhombi's u1: with a corner
    // on top (rotation 0) the edges are vertical and the passes run at 90 and 90 +- 120 deg; with
    // a flat top (30) at 0 and +-120, as published.
    const float angle = RhombusBlurPass::directions(f.bladeRotationDeg).u1 + 120.0f * static_cast<float>(node.turn);
    const auto input = [&](std::size_t i) -> const gl::Texture& { return texture(node.reads[i], out); };
    timer.begin(node.name, f.serial);
    switch (node.pass) {
    case PassKind::Coc:
        // The bokeh sprites first: the CoC pass leaves their light out of the gather if they fit
        // the frame's budget.
        if (f.plan.highlightSprites)
            highlightSpritePass.find(f.colorTexture, f.depth, f.cocParams, f.aperture, f.plan.nearField,
                                     neighbourhoods, f.analysis.highlightTiles,
                                     HighlightSpritePass::budget(static_cast<std::size_t>(size.area()),
                                                                 f.analysis.highlightPixels));
        cocPass.run(f.colorTexture, f.depth, f.cocParams, drawTarget(node, out), blurShift, &neighbourhoods,
                    &highlightSpritePass.sprites(), &highlightTiles);
        break;
    case PassKind::RhombiLines:
    case PassKind::RhombiDiagonals:
    case PassKind::RhombiComposite: {
        const bool first = node.pass == PassKind::RhombiLines;
        const bool fused = node.pass == PassKind::RhombiComposite;
        const gl::Framebuffer& target = drawTarget(node, out);
        rhombusBlurPass.run({input(0), first ? nullptr : &input(1), near, target}, first, f.directions, samples,
                            tileSize(), tiles, fused, f.plan.unrolledTaps);
        if (f.useTiles)
            copyPass.run(input(0), copyTiles, target, !fused);
        break;
    }
    case PassKind::McIntoshBlur: {
        const gl::Framebuffer& target = drawTarget(node, out);
        hexBlurPass.run(input(0), f.depth, angle, samples, target, tiles);
        if (f.useTiles)
            copyPass.run(input(0), copyTiles, target);
        break;
    }
    case PassKind::NearBlur:
        nearBlurPass.run(input(0), nearDiameter, angle, samples, node.turn == 0, drawTarget(node, out), nearTiles);
        break;
    case PassKind::Composite:
        if (f.quality.kernel == HexagonKernel::RhombiSum)
            compositePass.runSum(input(0), input(1), drawTarget(node, out));
        else
            compositePass.run(input(0), input(1), drawTarget(node, out), f.plan.nearField ? &input(2) : nullptr,
                              f.plan.nearField ? &input(3) : nullptr);
        break;
    case PassKind::Prefilter:
    case PassKind::Upscale: {
        const gl::Framebuffer& prefiltered = pool.pair(image(Image::Sharpened), image(Image::Added), "prefilter");
        const UpscalePass::Io io{f.colorTexture, f.depth, texture(Image::Coc, out),
                                 image(Image::Blurred).texture, image(Image::Sharpened).texture,
                                 image(Image::Added).texture, prefiltered, out->framebuffer};
        if (node.pass == PassKind::Prefilter)
            upscalePass.prefilter(io);
        else
            upscalePass.upscale(io, f.cocParams, blurShift, f.upscaleUsesTiles ? &detailTiles : nullptr);
        break;
    }
    case PassKind::HighlightSprites:
        highlightSpritePass.draw(f.cocParams, f.depth, out->framebuffer);
        break;
    case PassKind::InFocusLight:
        inFocusLightPass.run({f.colorTexture, f.depth, texture(Image::Coc, out), near}, f.cocParams, f.directions, samples, tileSize(), blurShift, frameHighlightTiles, out->framebuffer);
        break;
    case PassKind::ViewImage: {
        if (node.view == View::Depth) {
            viewLow = std::max(f.nearestDepth, 1e-3f);
            viewHigh = std::max(f.farthestDepth, f.nearestDepth * 1.01f + 1e-3f);
            viewPass.run(f.depth, ViewPass::Mode::Depth, viewLow, viewHigh, out->framebuffer);
        } else if (node.view == View::Coc) {
            // The lens' CoC in the target's pixels; the target holds the gather's.
            viewHigh = f.maxCocPx / static_cast<float>(1 << blurShift);
            viewPass.run(input(0), ViewPass::Mode::Coc, 0.0f, viewHigh * f.gatherScale, out->framebuffer);
        } else {
            viewPass.run(input(0), ViewPass::Mode::Color, 0.0f, 0.0f, out->framebuffer);
        }
        break;
    }
    case PassKind::OutputCopy:
        outputCopyPass.run(out->texture, out->generation, *caller, bgra);
        break;
    case PassKind::YuvToRgb:
    case PassKind::DepthPrep:
    case PassKind::SceneMeasure:
        CV_Error(cv::Error::StsInternal, std::string(node.name) + " runs when a frame is begun (prepare())");
    }
    timer.end();
    for (const Image image : node.writes)
        f.written[static_cast<std::size_t>(image)] = true;
}

void Pipeline::Impl::render()
{
    FrameContext& f = current;
    if (!f.depthPrepared)
        planFrame(); // the all-in-focus exit, rendered for a view or readTarget()
    const auto start = Clock::now();
    pool.nextFrame();
    f.images.fill(nullptr);
    std::fill(f.written.begin(), f.written.end(), false);

    // Tiles in focus are copied, not blurred, when enough of them are: a thousand small quads
    // cost the rasteriser more than one full-screen triangle (on llvmpipe, drawing 1181 of 1200
    // tiles took 25 % longer than the whole frame), so a few copy tiles are not worth it.
    f.useTiles = f.quality.adaptive && !f.plan.copyTiles.empty() &&
                 f.plan.copyTiles.size() * 4 >= f.plan.copyTiles.size() + f.plan.blurTiles.size();
    if (f.useTiles) {
        blurTiles.set(f.plan.blurTiles, blurSize, tileSize());
        copyTiles.set(f.plan.copyTiles, blurSize, tileSize());
    }
    // The upscale's detail on tiles by the same rule: when a quarter of them only interpolate.
    f.upscaleUsesTiles = f.quality.adaptive && blurShift != 0 &&
                         f.plan.detailTiles.size() * 4 <= static_cast<std::size_t>(f.analysis.tiles.area()) * 3;
    if (f.upscaleUsesTiles)
        detailTiles.set(f.plan.detailTiles, size, SceneAnalysis::kTileSize);
    if (f.plan.nearField) {
        uploadNearDiameter();
        if (f.quality.kernel == HexagonKernel::McIntoshMin)
            nearTiles.set(f.plan.nearTiles, blurSize, tileSize());
    }
    if (f.plan.highlightSprites) {
        CV_Assert(f.analysis.tileNeighbourhood.type() == CV_32FC4 && f.analysis.tileNeighbourhood.isContinuous());
        const auto bytes = static_cast<GLsizeiptr>(f.analysis.tileNeighbourhood.total() * sizeof(cv::Vec4f));
        if (neighbourhoods.size() != bytes)
            neighbourhoods = gl::StorageBuffer(bytes, "tile neighbourhoods");
        neighbourhoods.update(f.analysis.tileNeighbourhood.data, bytes);
    }
    // Highlight recovery only for 8-bit frames that have clipped pixels (the plan's highlights).
    if (f.plan.highlightSprites || f.plan.highlightGain > 1.0)
        highlightTiles.set(f.analysis.highlightTiles, blurSize, tileSize());
    if (f.plan.highlightSprites)
        frameHighlightTiles.set(f.analysis.highlightTiles, size, SceneAnalysis::kTileSize);
    f.cocParams.set(f.coefficients, f.quality.targetFormat == TargetFormat::Rgba16F,
                          static_cast<float>(f.plan.highlightGain),
                          f.plan.highlightSprites ? HighlightSpritePass::kThreshold : 0.0f);
    glBindVertexArray(vao.id());
    for (const Node& node : frameNodes(choices()))
        run(node, nullptr, nullptr, false);
    f.timings.renderMs = msSince(start);
    f.rendered = true;
}

Target& Pipeline::Impl::output(Encoding encoding)
{
    const bool srgb = encoding != Encoding::Linear32F;
    Target& out = srgb ? outSrgb : outLinear;
    out.ensure(srgb ? GL_SRGB8_ALPHA8 : GL_RGBA32F, size, srgb ? "output sRGB" : "output linear");
    return out;
}

void Pipeline::Impl::renderView(View view, const Target& out, const gl::Framebuffer* caller, bool bgra)
{
    if (!current.rendered)
        render();
    glBindVertexArray(vao.id());
    for (const Node& node : viewNodes(choices(), view, current.written, caller != nullptr))
        run(node, &out, caller, bgra);
}

void Pipeline::Impl::finishTimings(Clock::time_point readStart)
{
    current.timings.readbackMs = msSince(readStart);
    current.timings.gpu.clear();
    for (auto& [name, ms] : timer.swap(current.serial))
        current.timings.gpu.push_back({name, ms});
    current.timings.gpuFrame = gpuFrameIndex;
    gpuFrameIndex = current.frameIndex;
    current.timings.totalMs = current.spentMs();
}

namespace {

/// The image type read() returns for `encoding`.
int imageType(Encoding encoding)
{
    switch (encoding) {
    case Encoding::Srgb8: return CV_8UC3;
    case Encoding::Srgb8Bgra: return CV_8UC4;
    case Encoding::Linear32F: return CV_32FC3;
    }
    return CV_8UC3;
}

/// `from` into `to`, of its size and type: in stripes on OpenCV's threads where both are one
/// block of memory.
void copyImage(const cv::Mat& from, cv::Mat& to)
{
    if (from.isContinuous() && to.isContinuous())
        gl::copyFrameBytes(to.data, from.data, from.total() * from.elemSize());
    else
        from.copyTo(to);
}

/// A frame all in focus as `encoding` asks: 8-bit input bit-exact (BGRx's fourth byte made 255),
/// float input from `linear`, its cleaned-up copy. 8-bit input as 8-bit output goes into `out`
/// (of the colour's size and imageType(encoding); empty otherwise).
cv::Mat passThrough(const cv::Mat& color, const cv::Mat& linear, Encoding encoding, cv::Mat out)
{
    if (color.depth() != CV_8U) {
        if (encoding == Encoding::Linear32F)
            return linear;
        cv::Mat srgb = encodeSrgb(linear), bgra;
        if (encoding == Encoding::Srgb8)
            return srgb;
        cv::cvtColor(srgb, bgra, cv::COLOR_BGR2BGRA);
        return bgra;
    }
    if (encoding == Encoding::Srgb8Bgra) {
        if (color.channels() == 3) {
            cv::cvtColor(color, out, cv::COLOR_BGR2BGRA);
        } else {
            copyImage(color, out);
            const int toAlpha[] = {0, 3};
            const cv::Mat opaque(color.size(), CV_8UC1, cv::Scalar(255));
            cv::mixChannels(&opaque, 1, &out, 1, toAlpha, 1);
        }
        return out;
    }
    if (encoding == Encoding::Linear32F) {
        cv::Mat bgr = color;
        if (color.channels() == 4)
            cv::cvtColor(color, bgr, cv::COLOR_BGRA2BGR);
        return decodeSrgb(bgr);
    }
    if (color.channels() == 4)
        cv::cvtColor(color, out, cv::COLOR_BGRA2BGR);
    else
        copyImage(color, out);
    return out;
}

} // namespace

struct PendingRead::State {
    cv::Mat ready;              ///< the image, where it needed no read from the GPU
    gl::ReadbackBuffer buffer;  ///< otherwise the read in flight
    cv::Size size;
    Encoding encoding = Encoding::Srgb8;
    View view = View::Composite;
    float low = 0.0f, high = 0.0f; ///< the legend's ends (depth and CoC views)
    FrameTimings timings;
};

PendingRead::PendingRead() = default;
PendingRead::~PendingRead() = default;
PendingRead::PendingRead(PendingRead&&) noexcept = default;
PendingRead& PendingRead::operator=(PendingRead&&) noexcept = default;

const FrameTimings& PendingRead::timings() const
{
    static const FrameTimings none;
    return state_ ? state_->timings : none;
}

cv::Mat Pipeline::read(View view, Encoding encoding)
{
    PendingRead pending = readAsync(view, encoding);
    cv::Mat image = collect(pending);
    impl_->current.timings = pending.timings();
    return image;
}

PendingRead Pipeline::readAsync(View view, Encoding encoding)
{
    Impl& p = *impl_;
    CV_Assert(!p.size.empty());
    const auto start = Clock::now();
    PendingRead pending;
    pending.state_ = std::make_unique<PendingRead::State>();
    PendingRead::State& read = *pending.state_;
    read.size = p.size;
    read.encoding = encoding;
    read.view = view;
    if (view == View::Composite && !p.current.rendered) {
        // All in focus: the input is the output, bit-exact for 8-bit input; float input gets the
        // CoC pass's clean-up (no NaN, no negatives, within the target's range).
        // Y'CbCr: the bytes the GPU would have made of it.
        const bool converted = p.current.color.empty();
        const cv::Mat color = converted ? convertYuv(p.current.yuv) : p.current.color;
        const bool srgbInput = color.depth() == CV_8U;
        const bool half = p.current.quality.targetFormat == TargetFormat::Rgba16F;
        const cv::Mat linear = srgbInput ? cv::Mat() : sanitizeLinear(color, CocParams::largestColor(half));
        if (converted && encoding == Encoding::Srgb8) // the conversion is the pipeline's own
            read.ready = color;
        else // into an image of the pool, as a read from the GPU goes
            read.ready = passThrough(color, linear, encoding,
                                     srgbInput && encoding != Encoding::Linear32F
                                         ? p.takeOutput(p.size, imageType(encoding))
                                         : cv::Mat());
        p.current.timings.readbackMs = msSince(start);
        p.current.timings.totalMs = p.current.spentMs();
        read.timings = p.current.timings;
        return pending;
    }
    const Target& out = p.output(encoding);
    p.renderView(view, out);
    read.low = p.viewLow;
    read.high = p.viewHigh;
    // Into a buffer of the pool behind a fence: the pixels travel while the caller goes on.
    const int type = imageType(encoding);
    read.buffer = p.takeReadbackBuffer(static_cast<GLsizeiptr>(p.size.area()) * CV_ELEM_SIZE(type));
    // The sRGB target's alpha is 1 wherever the passes write: BGRA reads it as 255.
    read.buffer.readPixels(out.framebuffer.id(), p.size.width, p.size.height, CV_MAT_CN(type) == 4 ? GL_BGRA : GL_BGR,
                           CV_MAT_DEPTH(type) == CV_32F ? GL_FLOAT : GL_UNSIGNED_BYTE);
    p.finishTimings(start);
    read.timings = p.current.timings;
    return pending;
}

cv::Mat Pipeline::collect(PendingRead& pending)
{
    CV_Assert(pending.state_);
    PendingRead::State& read = *pending.state_;
    if (!read.ready.empty())
        return std::exchange(read.ready, cv::Mat());
    const auto start = Clock::now();
    cv::Mat image = impl_->takeOutput(read.size, imageType(read.encoding));
    read.buffer.copyTo(image.data, static_cast<GLsizeiptr>(image.total() * image.elemSize()));
    impl_->spareReadbacks.push_back(std::move(read.buffer));
    if (read.view == View::Depth)
        drawLegend(image, LegendKind::DepthMetres, read.low, read.high);
    else if (read.view == View::Coc)
        drawLegend(image, LegendKind::SignedCocPixels, -read.high, read.high);
    const double waitedMs = msSince(start);
    read.timings.readbackMs += waitedMs;
    read.timings.totalMs += waitedMs;
    return image;
}

void Pipeline::readInto(View view, unsigned texture, bool bgra)
{
    Impl& p = *impl_;
    CV_Assert(!p.size.empty());
    if ((view == View::Composite && !p.current.rendered) || view == View::Depth || view == View::Coc) {
        // The input as it came, or a legend drawn on the CPU: read() and uploaded. Three
        // components into RGBA8 give alpha 1; BGR bytes read as RGB put blue in red.
        const cv::Mat image = read(view, Encoding::Srgb8);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glTextureSubImage2D(texture, 0, 0, 0, p.size.width, p.size.height, bgra ? GL_RGB : GL_BGR,
                            GL_UNSIGNED_BYTE, image.data);
        return;
    }
    const auto start = Clock::now();
    const gl::Framebuffer target(texture, p.size.width, p.size.height, "caller's output");
    p.renderView(view, p.output(Encoding::Srgb8), &target, bgra);
    p.finishTimings(start);
}

cv::Mat Pipeline::run(const Frame& frame, const LensSettings& lens, const QualitySettings& quality, View view,
                      Encoding encoding)
{
    process(frame, lens, quality);
    return read(view, encoding);
}

cv::Mat Pipeline::readTarget(View view)
{
    Impl& p = *impl_;
    if (!p.current.rendered)
        p.render();
    // The view's nodes but the last, which would draw the view: what writes the target.
    std::vector<Node> nodes = viewNodes(p.choices(), view, p.current.written);
    CV_Assert(view != View::Composite && view != View::Depth && view != View::Coc && !nodes.empty());
    nodes.pop_back();
    glBindVertexArray(p.vao.id());
    for (const Node& node : nodes)
        p.run(node, nullptr, nullptr, false);
    const Target& target = p.image(viewedImage(view));
    cv::Mat image(target.texture.height(), target.texture.width(), CV_32FC4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, target.framebuffer.id());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, image.cols, image.rows, GL_RGBA, GL_FLOAT, image.data);
    return image;
}

const cv::Mat& Pipeline::filledDepth()
{
    Impl& p = *impl_;
    if (!p.current.depthPrepared)
        p.planFrame();
    if (!p.current.preparedOnCpu) {
        p.current.prepared.metres.create(p.size, CV_32FC1);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        cv::Mat& metres = p.current.prepared.metres;
        glGetTextureImage(p.current.depth.id(), 0, GL_RED, GL_FLOAT, static_cast<GLsizei>(metres.total() * 4),
                          metres.data);
        p.current.prepared.invalidFraction = p.current.invalidFraction;
        p.current.preparedOnCpu = true;
    }
    return p.current.prepared.metres;
}

void Pipeline::prepareOnGpu(bool on)
{
    impl_->prepareOnGpu = on;
}

void Pipeline::computePasses(bool on)
{
    impl_->setStage(on ? ShaderStage::Compute : ShaderStage::Fragment);
}

double Pipeline::invalidDepthFraction() const
{
    return impl_->current.invalidFraction;
}


const FrameTimings& Pipeline::timings() const
{
    return impl_->current.timings;
}

std::vector<PassTime> Pipeline::drainGpuTimes()
{
    std::vector<PassTime> times;
    for (auto& [name, ms] : impl_->timer.drain())
        times.push_back({name, ms});
    return times;
}

void Pipeline::finishEachPass(bool on)
{
    impl_->timer.finishEachScope(on);
}

std::size_t Pipeline::targetsHeld() const
{
    const auto& images = impl_->current.images;
    return static_cast<std::size_t>(std::count_if(images.begin(), images.end(), [](const Target* t) { return t; }));
}

const SceneAnalysis& Pipeline::analysis() const
{
    return impl_->current.analysis;
}

const FramePlan& Pipeline::plan() const
{
    return impl_->current.plan;
}

} // namespace defocus
