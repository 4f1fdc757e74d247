// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus::Filter: gives one colour frame + its depth the depth of field of a real lens, with
// hexagonal bokeh, on a headless OpenGL 4.5 context of its own (a GPU, or Mesa llvmpipe).
//   defocus::Settings s;  s.lens.focusM = 1.0;  s.lens.fNumber = 1.4;
//   defocus::Filter filter(s);                           // throws GlError without GL 4.5
//   cv::Mat out = filter.process(bgr8, depth16);         // depth16 in s.depthScale units/metre
//
// Threads: a Filter is not thread-safe; call it from one thread at a time (any thread, one after
// another; where a call finds another thread inside one it throws GlError). Each call that renders
// (construction, process(), contactSheet(), finishGpuTimings(), the destructor) makes the
// Filter's EGL context current on the calling thread for its duration and then puts back what
// was current there before (another EGL context of the caller's, or none), so no release() is
// needed between threads. Different Filters are independent and may run on different threads
// at once. A Filter made with ContextOptions::callerContext makes no context current: the
// caller's must be current on the calling thread for every call and the destructor. check(),
// version(), eglDevices(), probeRenderer() and the structs are plain data and functions that any
// thread may call (probeRenderer() makes and drops a context of its own).
// Several clips, one after the other, can share one Filter (one context, one shader build):
// setSettings() and reset() between them, as `defocus --batch` does.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "defocus/Export.hpp"
#include "defocus/Frame.hpp"
#include "defocus/Settings.hpp"

namespace defocus {

/// Every error the library throws; what() is one line that names the parameter or image.
class DEFOCUS_API Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};
/// A setting out of range, with the command line's message ("--f-number must be between 0.7 and 64, not 0.5").
class DEFOCUS_API SettingsError : public Error {
public:
    using Error::Error;
};
/// A colour or depth image of a type or size the filter cannot take.
class DEFOCUS_API InputError : public Error {
public:
    using Error::Error;
};
/// No EGL display or OpenGL 4.5 context, or a driver that rejects a shader: says what was tried.
class DEFOCUS_API GlError : public Error {
public:
    using Error::Error;
};

/// Where the time of one frame went, milliseconds.
struct Timings {
    double totalMs = 0.0;     ///< process(), wall clock
    /// Depth resized to the colour, its holes filled and the scene measured: submitting the
    /// GPU's passes, or the CPU's work on a software renderer (llvmpipe), where that is faster.
    double depthPrepMs = 0.0;
    double analysisMs = 0.0;  ///< waiting for the measurement, the scene analysis and the plan
    double uploadMs = 0.0;    ///< colour and depth to the GPU
    double renderMs = 0.0;    ///< submitting the passes
    double readbackMs = 0.0;  ///< the output pass and reading the result back
    struct Pass {
        std::string name; ///< e.g. "coc", "rhombi-1", "rhombi-2", "upscale"
        double ms = 0.0;  ///< GPU time
    };
    /// GPU time per pass of frame `gpuFrame`, read one frame late so that the GPU is never
    /// waited for; empty on the first frame and where the driver has no timer queries.
    std::vector<Pass> gpu;
    std::size_t gpuFrame = 0;
};

/// What the frame called for and what ran (the command line's --explain).
struct Plan {
    bool allInFocus = false;          ///< no blur anywhere: the output is the input, no pass ran
    std::size_t tiles = 0;            ///< tiles of the frame (SceneAnalysis' 16x16 pixels)
    std::size_t blurTiles = 0;        ///< tiles the blur passes processed
    std::size_t copyTiles = 0;        ///< tiles only copied (in focus)
    bool holeFill = false;            ///< the depth had holes, filled from valid neighbours
    double invalidDepthFraction = 0;  ///< share of the depth that had no measurement, [0, 1]
    bool nearField = false;           ///< the foreground's own blur ran
    bool highlightSprites = false;    ///< lights were scattered as hexagons
    int tileSizePx = 16;              ///< side of a tile, pixels
    /// One byte per tile (CV_8UC1, tiles across by tiles down, the last row and column possibly
    /// cut by the frame's edge): 1 where the tile's blur reaches half a pixel, so the blur passes
    /// process it, 0 where it is in focus and only copied. What the preview's tile map outlines.
    cv::Mat tileMap;
    std::string explain;              ///< one line, as `defocus --explain` prints it
};

/// Where the filter renders. Chosen once, when the Filter is made.
struct ContextOptions {
    /// EGL device to render on, only that one (an index of eglDevices()). nullopt: the GPU that
    /// CUDA_VISIBLE_DEVICES makes CUDA's first, else the first device that works, else Mesa's
    /// surfaceless platform. The command line's --egl-device.
    std::optional<int> eglDevice;
    /// Render on the OpenGL context current on the thread that makes the Filter (an EGL or GLX
    /// context of the caller's, e.g. a GstGLContext on its own thread) and make none: eglDevice is
    /// not used. It must be OpenGL 4.5 core or later (GlError otherwise), current whenever the
    /// Filter is called or destroyed, and share no state the caller relies on across a call but
    /// what the Filter documents (processTextures()). The Filter's GL objects live in it.
    bool callerContext = false;
};

/// One frame in GL_TEXTURE_2D textures of the caller's context, for Filter::processTextures().
/// Texture formats are those GStreamer's GL memory uses for these video formats.
struct GlFrame {
    enum class Order { Rgba, Bgra };
    enum class DepthFormat {
        R16,   ///< GL_R16: 16-bit units, Settings::depthScale per metre
        Rg8Le, ///< GL_RG8 holding 16-bit little-endian units (red the low byte): GStreamer's GRAY16_LE
        R32F   ///< GL_R32F: metres
    };
    unsigned color = 0;       ///< GL_RGBA8 (not an sRGB format), sRGB-encoded values, alpha ignored
    Order colorOrder = Order::Rgba; ///< Bgra: red holds blue (GStreamer's BGRA/BGRx in GL memory)
    unsigned depth = 0;       ///< any size with the colour's aspect ratio; 0 = all in focus
    DepthFormat depthFormat = DepthFormat::R16;
    unsigned output = 0;      ///< GL_RGBA8 at the colour's size, written whole: sRGB-encoded, alpha 1
    Order outputOrder = Order::Rgba;
    int width = 0, height = 0; ///< the colour's and the output's size, pixels
};

/// One EGL device of the machine (the command line's `--info` lists them).
struct EglDevice {
    int index = 0;              ///< what ContextOptions::eglDevice takes
    bool software = false;      ///< a software renderer (Mesa llvmpipe)
    std::string drmFile;        ///< e.g. "/dev/dri/card1"; empty where the driver does not say
    std::optional<int> cudaId;  ///< the CUDA device it is, as this process's CUDA numbers them
};

/// The context a Filter renders in.
struct RendererInfo {
    std::string platform;    ///< EGL platform: "device" or "surfaceless"
    int eglDevice = -1;      ///< index of the EGL device in use; -1 on the surfaceless platform
    std::string eglVendor;   ///< EGL_VENDOR
    std::string eglVersion;  ///< EGL_VERSION
    std::string glVendor;    ///< GL_VENDOR
    std::string glRenderer;  ///< GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    std::string glVersion;   ///< GL_VERSION
    bool timerQueries = false; ///< the driver has GPU timer queries (Timings::gpu is filled)
    /// Depth preparation and the scene measurement run on the GPU (the frame's depth goes up as
    /// it came); on a software renderer (llvmpipe) the CPU does them, which is faster there.
    /// DEFOCUS_DEPTH_PREP=gpu or cpu chooses on any renderer.
    bool depthPrepOnGpu = false;
    /// The presets' render targets are half float (Quality::precision left to the renderer):
    /// on a GPU; full float on a software renderer.
    bool halfFloatTargets = false;
    /// The passes run as compute shaders (on a GPU), or draw with fragment shaders (on a
    /// software renderer). DEFOCUS_PASSES=compute or fragment chooses on any renderer.
    bool computePasses = false;
};

/// The EGL display (an initialised EGLDisplay) a Filter with a context of its own renders on
/// here, kept open for the rest of the process: for a caller that must share one, such as
/// GStreamer's GL library on a machine with no window system and no /dev/dri
/// (gst_gl_display_egl_new_with_egl_display). Throws GlError where no context can be made.
DEFOCUS_API void* eglDisplay(const ContextOptions& context = {});
/// `image` as the filter sees it: CV_8UC3 BGR, each pixel from its own Y' and the Cb and Cr of its
/// 2x2 block or YUYV pair (nearest, as OpenCV's cvtColor and video players' fast paths take
/// them), in 8-bit fixed point with the coefficients of its matrix and range (BT.601 limited:
/// within one level of cv::cvtColor's COLOR_YUV2BGR_I420). Throws InputError for planes of the
/// wrong type or size.
DEFOCUS_API cv::Mat yuvToBgr(const YuvImage& image);
/// The EGL devices of this machine; empty where EGL cannot enumerate them.
DEFOCUS_API std::vector<EglDevice> eglDevices();
/// Makes an OpenGL 4.5 context as a Filter would (no shaders compiled), says what it is and
/// drops it. Throws GlError where none can be made.
DEFOCUS_API RendererInfo probeRenderer(const ContextOptions& context = {});

/// The last processed frame.
struct FrameReport {
    std::size_t index = 0; ///< frames since construction or reset(), from 0
    double focusM = 0.0;   ///< focus distance used, metres (the autofocus' when it is on)
    Timings timings;
    Plan plan;
};

class DEFOCUS_API Filter {
public:
    /// Creates the EGL context and compiles the shaders: the first Filter of a process takes a
    /// second or more on llvmpipe. Throws SettingsError for settings out of range and GlError
    /// where no OpenGL 4.5 context can be made.
    explicit Filter(const Settings& settings = {});
    /// The same, on the device that `context` chooses.
    Filter(const Settings& settings, const ContextOptions& context);
    ~Filter();
    Filter(Filter&&) noexcept;
    Filter& operator=(Filter&&) noexcept;
    Filter(const Filter&) = delete;
    Filter& operator=(const Filter&) = delete;

    /// Replaces the settings from the next process() on. Throws SettingsError (the settings
    /// stay as they were) when any is out of range; check() with clamp first to accept anything.
    void setSettings(const Settings& settings);
    const Settings& settings() const;

    /// Filters one frame and returns the result, the colour's size (Settings::output says
    /// how it is encoded).
    /// `color`: BGR, CV_8UC3 sRGB-encoded (CV_8UC4: BGRx, uploaded as it is, the fourth channel
    /// ignored; Settings::Output::Srgb8Bgra returns the same four bytes a pixel) or CV_32FC3
    /// scene-linear. `depth`: along the view axis, CV_16UC1 in Settings::depthScale units per
    /// metre (uploaded as it is and converted on the GPU; on the CPU where depth prep runs there)
    /// or CV_32FC1 metres; 0, NaN and infinities mean "no measurement" (filled from valid
    /// neighbours); any size with the colour's aspect ratio (resized by nearest neighbour); empty
    /// = all in focus. Either may be a view into a larger image (`image(cv::Rect(...))`; the
    /// colour is copied then). `timestampS`: capture time, seconds (AutofocusOptions::Mode::Follow steps by the time
    /// between frames; 0 = unknown, taken as 1/30 s). Throws InputError for images it cannot
    /// take and SettingsError when an automatic focus comes out of range.
    cv::Mat process(const cv::Mat& color, const cv::Mat& depth, double timestampS = 0.0);
    /// process() of colour as video decoders and cameras give it (YuvImage: I420, NV12 or YUYV,
    /// its planes views or not): the same bytes as process(yuvToBgr(color), depth, timestampS).
    /// On a GPU the planes go up as they are (1.5 bytes a pixel for 4:2:0, 2 for YUYV, instead
    /// of BGR's 3) and become colour there; on a software renderer the CPU converts them. Throws InputError for planes
    /// of the wrong type or size.
    cv::Mat process(const YuvImage& color, const cv::Mat& depth, double timestampS = 0.0);
    /// process() of a frame as a Source gives it: its colour (`color`, or `yuv` where `color` is
    /// empty), its depth and its timestamp. 16-bit depth whose Frame::depthScale is not
    /// Settings::depthScale goes in as metres (depthMetres()); otherwise as it is.
    cv::Mat process(const Frame& frame);
    /// process() for a frame in textures of the caller's context (ContextOptions::callerContext;
    /// otherwise it throws InputError): the same result as process() of the same images, byte for
    /// byte, into `frame.output` (Settings::output is taken as Srgb8). Call it on the thread where
    /// that context is current. The colour and depth are read back (glGetTextureImage) and go
    /// through depth preparation and the scene measurement as process()'s do; the output is
    /// rendered on the GPU, except frames all in focus and the depth and coc views, which are
    /// uploaded. The call waits for no fence: the
    /// caller orders its own work around it (GStreamer: GstGLSyncMeta). GL state: it puts back the
    /// framebuffer bindings, viewport, program, vertex array, active texture, the 2D texture and
    /// sampler bindings of units 0-7, pixel-store alignment and row length, the pixel pack and
    /// unpack, draw-indirect and generic uniform and shader-storage buffers, blend function and
    /// equation, colour mask and the enables of FRAMEBUFFER_SRGB, BLEND, DEPTH_TEST, STENCIL_TEST,
    /// SCISSOR_TEST and CULL_FACE (construction, process() and the other calls on such a Filter
    /// do the same); it leaves the indexed uniform and shader-storage buffer bindings changed.
    /// Throws InputError for textures that are not 2D of the format and size stated.
    void processTextures(const GlFrame& frame, double timestampS = 0.0);

    /// Frames in flight, for throughput (as FFmpeg's send/receive): submit() takes a frame as
    /// process() does, uploads it and queues its depth preparation and scene measurement, then
    /// plans the frame submitted before it and queues its passes and its read, and returns
    /// without waiting for the GPU's passes; receive() returns the oldest submitted frame's
    /// result, the bytes process() would have returned for it (planning it first if no submit()
    /// has), waiting for it, and makes lastFrame() that frame's report (its totalMs and
    /// readbackMs: the time spent on it in its submit(), the next and receive(), not the time
    /// it waited between them); nullopt when none is in flight. With kFramesInFlight submitted
    /// before each receive(), the GPU measures a frame and runs the passes of the one before
    /// while the CPU plans; the CPU's own work (upload, or depth preparation on a software
    /// renderer) overlaps the GPU's. The images are
    /// referenced until the frame is received: leave their pixels unchanged until then.
    /// Settings changed between submits apply from the next submit. While frames are in flight,
    /// process() and contactSheet() throw Error; reset() drops them. Not for a Filter on the
    /// caller's context (processTextures()).
    void submit(const cv::Mat& color, const cv::Mat& depth, double timestampS = 0.0);
    /// submit() of Y'CbCr colour, as process() takes it; its planes are referenced until received.
    void submit(const YuvImage& color, const cv::Mat& depth, double timestampS = 0.0);
    /// submit() of a frame as a Source gives it, as process(const Frame&) takes it.
    void submit(const Frame& frame);
    std::optional<cv::Mat> receive();
    /// Frames submitted and not yet received.
    std::size_t framesInFlight() const;
    /// How many frames to keep submitted for the CPU and the GPU to overlap.
    static constexpr std::size_t kFramesInFlight = 2;

    /// The last frame's timings and plan (valid after the first process()).
    const FrameReport& lastFrame() const;
    /// The GPU times of the last frame, waiting for the GPU (otherwise they come one frame late,
    /// with the next frame's Timings::gpu): call once at the end of a stream. They belong to
    /// frame lastFrame().index; empty before the first frame and without timer queries.
    std::vector<Timings::Pass> finishGpuTimings();
    /// Every view of the last processed frame (Settings::View, in its order, each labelled with
    /// its number and name) and the plan (tiles blurred outlined, copied dimmed, near field
    /// blue), read back as 8-bit sRGB and laid out on one labelled CV_8UC3 sheet, four to a
    /// row: the command line's --contact-sheet. Call it right after process(), with that call's
    /// images unchanged: the frame is processed again afterwards, so that lastFrame() and the
    /// GPU times stay those of a plain frame (lastFrame().index does not advance). Throws
    /// InputError before the first process().
    cv::Mat contactSheet();
    /// A new stream: the next frame is frame 0 again, and the autofocus measures afresh; frames
    /// still in flight are dropped.
    void reset();
    /// Unbinds the EGL context from the calling thread where it is still bound. Every call
    /// already unbinds it when it returns, so this is never needed to hand the Filter to
    /// another thread; it is kept for code written when it was.
    void release();
    /// The OpenGL renderer, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    std::string renderer() const;
    /// The context: platform, device, vendors and versions.
    RendererInfo rendererInfo() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace defocus
