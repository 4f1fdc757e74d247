// SPDX-License-Identifier: LGPL-2.1-or-later
// The depth-of-field pipeline, a frame at a time or one begun ahead: a frame whose valid depths
// all give less than half a pixel of CoC is passed through before anything else; otherwise
// upload, depth hole filling and the scene measurement (on the GPU, or on the CPU on a software
// renderer: prepareOnGpu()), the analysis and the per-frame plan (which tiles blur, which are copied, whether
// the near field, highlights and sprites run), the CoC pass, the blurs (QualitySettings::kernel:
// two passes of one-sided lines summed into three rhombi, the default, or McIntosh et al.'s three
// directional blurs and the min() of two), at full or half size (half: a prefilter and an upscale
// that puts the frame's in-focus pixels back), bokeh sprites for lights above white in the
// aperture's exact shape (any blade count, the circle, squeezed: filter/Aperture.hpp; the gather's
// hexagon is squeezed as the aperture is and covers its area), and the view read back. The passes
// are the nodes of the frame graph (filter/FrameGraph.hpp) that the plan picks, run in order;
// their images come from a pool of targets keyed by format and size, kept from frame to frame,
// so only what a node writes is made. Each frame's own textures, measurement, analysis, plan and
// the graph's progress (which targets it holds, what its nodes wrote) live in a frame context, so
// that the next frame can be uploaded and measured (begin()) before this one's passes run
// (finish()).
// Needs a current GL 4.5 context (gl::EglContext) for its whole life.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "defocus/Frame.hpp"
#include "filter/SceneAnalysis.hpp"
#include "filter/Settings.hpp"

namespace defocus {

/// How read() returns pixels.
enum class Encoding {
    Srgb8,     ///< CV_8UC3 BGR, sRGB-encoded (encoded on the GPU)
    Srgb8Bgra, ///< CV_8UC4 BGRA, sRGB-encoded, alpha 255 (GStreamer's BGRx and BGRA)
    Linear32F  ///< CV_32FC3 BGR, scene-linear, unclipped
};

struct PassTime {
    std::string name;
    double ms = 0.0;
};

/// Where the time of the last frame went. Wall times are CPU-side; `gpu` comes from timer
/// queries (empty when the driver has none).
struct FrameTimings {
    double depthPrepMs = 0.0; ///< resize + hole filling + measurement: submitting them, or on the CPU
    double analysisMs = 0.0;  ///< waiting for the GPU's measurement, the analysis and the plan
    double uploadMs = 0.0;    ///< colour + depth to textures
    double renderMs = 0.0;    ///< submitting the passes
    double readbackMs = 0.0;  ///< output pass + glReadPixels (waits for the GPU)
    /// process() + read(), wall clock; for a frame begun ahead, begin() + finish() + read(), not
    /// the wait between them.
    double totalMs = 0.0;
    /// GPU time per pass of frame `gpuFrame`: timer queries are read one frame late so that
    /// they never stall; empty on the first frame and when the driver has no timers.
    std::vector<PassTime> gpu;
    std::size_t gpuFrame = 0;
};

/// A view of a processed frame on its way back from the GPU (Pipeline::readAsync): the pixels
/// are read into a buffer behind a fence, and Pipeline::collect copies them out. Move-only; it
/// holds GL objects, so it ends with the pipeline's context current.
class PendingRead {
public:
    PendingRead();
    ~PendingRead();
    PendingRead(PendingRead&&) noexcept;
    PendingRead& operator=(PendingRead&&) noexcept;
    /// The frame's timings: readback and total so far at readAsync(), complete after collect().
    const FrameTimings& timings() const;

private:
    friend class Pipeline;
    struct State;
    std::unique_ptr<State> state_;
};

class Pipeline {
public:
    /// Compiles every pass; throws gl::ShaderError on a driver that rejects a shader.
    /// `timers`: use GL timer queries when the driver offers them.
    explicit Pipeline(bool timers = true);
    ~Pipeline();
    Pipeline(const Pipeline&) = delete;
    Pipeline& operator=(const Pipeline&) = delete;

    /// Runs the passes for `frame` (or only decides that nothing needs to run). `lens` and
    /// `quality` must have passed validate(). The frame's images are referenced, not copied,
    /// until the next process(): leave them unchanged until read() has been called.
    /// `depthUnitsPerMetre` 0: the frame's depth is CV_32FC1 metres; otherwise CV_16UC1 in those
    /// units (0: no measurement), uploaded as it is and converted on the GPU (converted on the
    /// CPU where depth prep runs there).
    /// `yuv`: the frame's colour as Y'CbCr planes (yuvProblem() found nothing wrong), with
    /// `frame.color` empty; uploaded as they came and converted on the GPU (YuvToRgbPass), or
    /// converted on the CPU (convertYuv()) where depth prep runs there.
    void process(const Frame& frame, const LensSettings& lens, const QualitySettings& quality,
                 double depthUnitsPerMetre = 0.0, const YuvImage* yuv = nullptr);
    /// process() in two halves, so that a frame's upload and measurement go ahead of the passes
    /// of the frame before it: begin() takes `frame`, uploads it and submits its depth prep and
    /// scene measurement (on the GPU; on the CPU it does them); finish() takes the oldest frame
    /// begun, plans it from its own measurement (waiting for the GPU only where it has not made
    /// it yet) and runs its passes, after which the reads and accessors are of it. Begun frames
    /// wait in order, each with its own textures; the reads stay of the frame finished last
    /// until the next finish(). begin(N + 1); finish() (of N) keeps the GPU busy with the
    /// passes of N - 1 while the CPU plans N. The same output as process(), and the same GPU
    /// timer scopes for each frame: a frame's depth prep and measurement are timed with its own
    /// passes, not with those of the frame read before it. The images are referenced until the
    /// frame's passes have run.
    void begin(const Frame& frame, const LensSettings& lens, const QualitySettings& quality,
               double depthUnitsPerMetre = 0.0, const YuvImage* yuv = nullptr);
    void finish();
    /// Frames begun and not finished.
    std::size_t begun() const;
    /// Forgets the frames begun and not finished.
    void dropBegun();
    /// Renders `view` of the last processed frame and reads it back. Depth and CoC views carry a
    /// legend along their bottom edge.
    cv::Mat read(View view, Encoding encoding);
    /// read(view, Srgb8) into `texture`, a GL_RGBA8 2D texture of the frame's size (a caller's,
    /// on this context): the same bytes, in RGBA order or with `bgra` BGRA, alpha 1. What the
    /// passes rendered is copied on the GPU (timer scope "output-copy"); a frame all in focus and
    /// the depth and coc views, whose legend is drawn on the CPU, are read() and uploaded.
    void readInto(View view, unsigned texture, bool bgra);
    /// read() in two halves, so that the next frame can be processed while this one is on its
    /// way back: readAsync() renders `view` and queues its read (a frame all in focus is ready
    /// at once); collect() waits for it and returns the pixels read() would have. Any number of
    /// frames may be pending, each collected once, in any order.
    PendingRead readAsync(View view, Encoding encoding);
    cv::Mat collect(PendingRead& read);
    /// process() + read() in one call.
    cv::Mat run(const Frame& frame, const LensSettings& lens, const QualitySettings& quality,
                View view = View::Composite, Encoding encoding = Encoding::Srgb8);

    /// Reads an intermediate target as CV_32FC4 RGBA (rgb linear, a = signed CoC in pixels),
    /// for tests and analysis: one of Input (the CoC pass), Horizontal, DiagonalA, DiagonalB.
    /// Renders the passes first where the frame skipped them (all in focus).
    cv::Mat readTarget(View view);

    /// The last frame's filled depth (CV_32FC1 metres). Fills the holes first where the frame
    /// skipped it (all in focus), which replaces the frame's timings, analysis and plan.
    const cv::Mat& filledDepth();
    /// The share of the last frame's depth that had no measurement, [0, 1]; recorded during
    /// process(), so asking runs nothing. At the colour's size; a frame all in focus counts it
    /// on the depth as given (the same share up to the nearest-neighbour resize).
    double invalidDepthFraction() const;
    /// Timings of the last process() + read() (of the last readAsync(), without its collect()).
    const FrameTimings& timings() const;
    /// GPU times of the last frame, waiting for them (call once at the end of a stream).
    std::vector<PassTime> drainGpuTimes();

    /// Profiling: wait for the GPU (glFinish) before and after every timed pass and report each
    /// pass's wall time in FrameTimings::gpu instead of its timer query. On llvmpipe, which
    /// renders when a flush or readback needs it, this is what puts each pass's cost on its
    /// own row; it removes the overlap of CPU and GPU work, so the frame is slower.
    void finishEachPass(bool on);

    /// Depth prep (resize, hole filling, the lights' edges) and the scene measurement on the GPU,
    /// the frame's depth uploaded as it came and only the measurement read back; or on the CPU,
    /// the filled depth uploaded (prepareDepth(), measureScene()). The same filled depth and plan
    /// either way (DepthPrepGLTest). The GPU by default, the CPU on a software renderer
    /// (llvmpipe), where it is faster; tests and benchmarks hold the two side by side.
    void prepareOnGpu(bool on);

    /// The passes that shade each pixel once (depth prep, CoC, rhombi, McIntosh's blurs,
    /// composite, copies, prefilter, upscale) as compute shaders, or drawn with their fragment
    /// shaders: the same shaders and the same frames (ComputePassesGLTest). Compute by default on
    /// a GPU, drawn on a software renderer (gl::computePasses()). The bokeh sprites and the light
    /// in focus blend into the output, and the views draw, either way.
    void computePasses(bool on);

    /// The pooled targets the last frame's nodes hold: one per image of FrameGraph's pool that
    /// a node it ran wrote, none for an image nothing writes (tests hold it to the graph).
    std::size_t targetsHeld() const;

    /// What the last frame called for, and what ran.
    const SceneAnalysis& analysis() const;
    const FramePlan& plan() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace defocus
