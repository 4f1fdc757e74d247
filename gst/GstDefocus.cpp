// SPDX-License-Identifier: LGPL-2.1-or-later
// The GStreamer element `defocus`: colour on the `color` pad, depth on the `depth` pad, the depth
// of field of a lens out of `src`, one frame per colour frame with its timestamp and duration,
// each paired with the depth current at its running time (a GstVideoAggregator that runs its own
// aggregate()). It uses only libdefocus' public API: in system memory on an EGL context of its
// own made on the streaming thread, with frames in flight (Filter::submit/receive) while colour
// frames queue up behind each other and never one held for input that has not come; in GL memory (video/x-raw(memory:GLMemory)) on the pipeline's
// GstGLContext, on its thread, with no frame mapped for the CPU, and where GStreamer's GL library
// finds no display (a server with no window system) on the library's headless EGL display, which it
// offers to its neighbours. The library's messages go to GStreamer's log (gst/LibraryLog.hpp).
//   gst-launch-1.0 defocus name=d focus=1.2 f-number=1.4 ! videoconvert ! autovideosink
//     filesrc location=clip.mp4 ! decodebin ! videoconvert ! d.color
//     filesrc location=depth.png ! pngdec ! imagefreeze ! d.depth         (one line)
//   gst-launch-1.0 defocus name=d ! glimagesink
//     filesrc location=clip.mp4 ! decodebin ! glupload ! glcolorconvert ! d.color
//     filesrc location=depth.png ! pngdec ! imagefreeze ! videoconvert ! glupload ! d.depth
#include "gst/GstDefocus.hpp"
#include "gst/GstDefocusSrc.hpp"
#include "gst/LibraryLog.hpp"

#include <atomic>
#include <cmath>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>

#include <defocus/defocus.hpp>
#include <EGL/egl.h>
#include <gst/gl/egl/gstgldisplay_egl.h>
#include <gst/gl/gl.h>
#include <opencv2/imgproc.hpp>

GST_DEBUG_CATEGORY_STATIC(gst_defocus_debug);
#define GST_CAT_DEFAULT gst_defocus_debug

namespace {

/// A colour frame submitted to the filter and not yet received: the element's own mappings of
/// its colour (as the colour pad prepared it, or I420, NV12 or YUY2 as it came) and of its depth,
/// which the filter reads until the frame is received, and what its output buffer takes.
struct InFlight {
    GstVideoFrame color{}, depth{};
    GstClockTime pts = GST_CLOCK_TIME_NONE, duration = GST_CLOCK_TIME_NONE;
    bool post = false; ///< post-timings when it was submitted
};

void unmap(InFlight& frame)
{
    if (frame.color.buffer)
        gst_video_frame_unmap(&frame.color);
    if (frame.depth.buffer)
        gst_video_frame_unmap(&frame.depth);
    frame.color = {};
    frame.depth = {};
}

/// What the element keeps besides the GObject: settings written by any thread (under `lock`),
/// the filter and its bookkeeping used by the streaming thread only.
struct State {
    std::mutex lock;
    defocus::Settings settings;     ///< as the properties say
    bool nearFieldSet = false;      ///< near-field was set: it overrides the quality preset
    bool postTimings = false;
    unsigned generation = 1;        ///< bumped by every property change
    GstVideoAggregatorPad* color = nullptr; ///< the request pads, or null (under the object lock)
    GstVideoAggregatorPad* depth = nullptr;

    // Streaming thread only.
    std::unique_ptr<defocus::Filter> filter;
    unsigned applied = 0;           ///< generation the filter has
    std::set<std::string> warned;   ///< settings problems already posted as warnings
    std::atomic<bool> resetPending{false}; ///< a flush happened: the next frame starts a new stream
    std::atomic<bool> depthStale{false};   ///< a flush happened: the depth frame is from before it
    GstBuffer* depthFrame = nullptr;       ///< the depth frame current at the last colour frame
    /// Frames submitted to `filter` and not yet received, oldest first (system memory).
    std::deque<InFlight> inFlight;
    GstClockTime depthEnd = GST_CLOCK_TIME_NONE; ///< its end, running time (NONE: no duration)
    GstClockTime lastDuration = GST_SECOND / 30; ///< the last colour frame's (a live deadline's step)

    // GL memory (under glLock): the pipeline's display and context, shared with the neighbours.
    std::recursive_mutex glLock;
    GstGLDisplay* display = nullptr;
    GstGLContext* otherContext = nullptr; ///< the application's (gst.gl.app_context), if any
    GstGLContext* glContext = nullptr;    ///< where the GL path renders
    std::atomic<bool> glOutput{false};    ///< the output's caps are GL memory
    /// The filter of the GL path: made, called and destroyed on glContext's thread.
    std::unique_ptr<defocus::Filter> glFilter;
};

} // namespace

struct _GstDefocus {
    GstVideoAggregator parent;
    State* state;
};

G_DEFINE_TYPE(GstDefocus, gst_defocus, GST_TYPE_VIDEO_AGGREGATOR)

namespace {

enum Property {
    PROP_0,
    PROP_FOCUS,
    PROP_AUTOFOCUS,
    PROP_AUTOFOCUS_TIME_CONSTANT,
    PROP_F_NUMBER,
    PROP_FOCAL_LENGTH,
    PROP_SENSOR_WIDTH,
    PROP_FOV_FROM,
    PROP_MAX_COC,
    PROP_COC_MODEL,
    PROP_NEAR,
    PROP_FAR,
    PROP_QUALITY,
    PROP_SAMPLES,
    PROP_HEXAGON,
    PROP_PRECISION,
    PROP_RESOLUTION,
    PROP_NEAR_FIELD,
    PROP_HIGHLIGHT_SPRITES,
    PROP_HIGHLIGHT_GAIN,
    PROP_BLADES,
    PROP_BLADE_ROTATION,
    PROP_APERTURE_RATIO,
    PROP_DEPTH_SCALE,
    PROP_VIEW,
    PROP_POST_TIMINGS,
};

// Enums: the value nicks are the command line's words. "from-quality" leaves the choice to the
// quality preset, as leaving out the flag does.
GType registerEnum(const char* name, const GEnumValue* values)
{
    const GType type = g_enum_register_static(name, values);
    gst_type_mark_as_plugin_api(type, static_cast<GstPluginAPIFlags>(0));
    return type;
}

GType fovFromType()
{
    static const GEnumValue values[] = {
        {0, "A real camera: its view narrows as it focuses closer", "image-distance"},
        {1, "Renderers (Blender Cycles, game engines)", "focal-length"},
        {0, nullptr, nullptr}};
    static const GType type = registerEnum("GstDefocusFovFrom", values);
    return type;
}

GType cocModelType()
{
    static const GEnumValue values[] = {{0, "Physical thin lens", "thin-lens"},
                                        {1, "Blur rises linearly from focus to max-coc at near and far", "focal-range"},
                                        {0, nullptr, nullptr}};
    static const GType type = registerEnum("GstDefocusCocModel", values);
    return type;
}

GType qualityType()
{
    static const GEnumValue values[] = {{0, "4 taps, half size", "fast"},
                                        {1, "6 taps, half size", "balanced"},
                                        {2, "12 taps, full size", "high"},
                                        {0, nullptr, nullptr}};
    static const GType type = registerEnum("GstDefocusQuality", values);
    return type;
}

GType hexagonType()
{
    static const GEnumValue values[] = {{0, "The quality preset's", "from-quality"},
                                        {1, "Three one-sided rhombi summed (keeps highlight energy)", "rhombi"},
                                        {2, "McIntosh et al. 2012, min of two", "mcintosh"},
                                        {0, nullptr, nullptr}};
    static const GType type = registerEnum("GstDefocusHexagon", values);
    return type;
}

GType precisionType()
{
    static const GEnumValue values[] = {{0, "The quality preset's", "from-quality"},
                                        {1, "16-bit float targets", "16f"},
                                        {2, "32-bit float targets", "32f"},
                                        {0, nullptr, nullptr}};
    static const GType type = registerEnum("GstDefocusPrecision", values);
    return type;
}

GType resolutionType()
{
    static const GEnumValue values[] = {{0, "The quality preset's", "from-quality"},
                                        {1, "Blurs at the frame's size", "full"},
                                        {2, "Blurs at half size (a quarter of the pixels)", "half"},
                                        {0, nullptr, nullptr}};
    static const GType type = registerEnum("GstDefocusResolution", values);
    return type;
}

GType viewType()
{
    static const GEnumValue values[] = {{0, "The colour the blur starts from", "input"},
                                        {1, "After the first blur pass", "horizontal"},
                                        {2, "Second pass, first diagonal", "diagonal-a"},
                                        {3, "Second pass, second diagonal", "diagonal-b"},
                                        {4, "The depth-of-field result", "composite"},
                                        {5, "Filled depth, colour-mapped, with a legend", "depth"},
                                        {6, "Signed blur diameter, colour-mapped, with a legend", "coc"},
                                        {0, nullptr, nullptr}};
    static const GType type = registerEnum("GstDefocusView", values);
    return type;
}

constexpr GParamFlags kFlags = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                        GST_PARAM_MUTABLE_PLAYING);
constexpr GParamFlags kControllable = static_cast<GParamFlags>(kFlags | GST_PARAM_CONTROLLABLE);

// Output formats: 8-bit RGB in the orders downstream elements ask for; the colour pad converts
// anything else (I420, NV12, YUY2, ...) to the one negotiated.
#define DEFOCUS_RGB_FORMATS "{ BGRx, BGRA, RGBx, RGBA, BGR, RGB }"
#define DEFOCUS_COLOR_FORMATS                                                                                       \
    "{ BGRx, BGRA, RGBx, RGBA, xRGB, xBGR, ARGB, ABGR, BGR, RGB, I420, YV12, NV12, NV21, YUY2, UYVY, Y42B, Y444, " \
    "GRAY8 }"

// GL memory: 8-bit RGBA textures (x: alpha ignored, written opaque), the output's memory the
// colour's; the depth as GStreamer's GL memory holds GRAY16_LE (an RG8 texture, low byte in red).
#define DEFOCUS_GL_CAPS(formats)                                                                                 \
    GST_VIDEO_CAPS_MAKE_WITH_FEATURES(GST_CAPS_FEATURE_MEMORY_GL_MEMORY, formats) ", texture-target = (string) 2D"
#define DEFOCUS_GL_RGB_FORMATS "{ RGBA, BGRA, RGBx, BGRx }"

GstStaticPadTemplate srcTemplate = GST_STATIC_PAD_TEMPLATE(
    "src", GST_PAD_SRC, GST_PAD_ALWAYS,
    GST_STATIC_CAPS(GST_VIDEO_CAPS_MAKE(DEFOCUS_RGB_FORMATS) "; " DEFOCUS_GL_CAPS(DEFOCUS_GL_RGB_FORMATS)));
GstStaticPadTemplate colorTemplate = GST_STATIC_PAD_TEMPLATE(
    "color", GST_PAD_SINK, GST_PAD_REQUEST,
    GST_STATIC_CAPS(GST_VIDEO_CAPS_MAKE(DEFOCUS_COLOR_FORMATS) "; " DEFOCUS_GL_CAPS(DEFOCUS_GL_RGB_FORMATS)));
// 16-bit depth in depth-scale units per metre; PNG decoders give big-endian.
GstStaticPadTemplate depthTemplate = GST_STATIC_PAD_TEMPLATE(
    "depth", GST_PAD_SINK, GST_PAD_REQUEST,
    GST_STATIC_CAPS(GST_VIDEO_CAPS_MAKE("{ GRAY16_LE, GRAY16_BE }") "; " DEFOCUS_GL_CAPS("GRAY16_LE")));

State& stateOf(gpointer self)
{
    return *GST_DEFOCUS(self)->state;
}

void setProperty(GObject* object, guint id, const GValue* value, GParamSpec* pspec)
{
    State& s = stateOf(object);
    bool autofocusOff = false;
    {
        std::lock_guard guard(s.lock);
        defocus::Settings& st = s.settings;
        switch (id) {
        case PROP_FOCUS:
            st.lens.focusM = g_value_get_double(value);
            // A focus set by hand (or by a control source) is manual focus.
            autofocusOff = st.autofocus.mode != defocus::AutofocusOptions::Mode::Off;
            st.autofocus.mode = defocus::AutofocusOptions::Mode::Off;
            break;
        case PROP_AUTOFOCUS:
            st.autofocus.mode = g_value_get_boolean(value) ? defocus::AutofocusOptions::Mode::Follow
                                                           : defocus::AutofocusOptions::Mode::Off;
            break;
        case PROP_AUTOFOCUS_TIME_CONSTANT: st.autofocus.timeConstantS = g_value_get_double(value); break;
        case PROP_F_NUMBER: st.lens.fNumber = g_value_get_double(value); break;
        case PROP_FOCAL_LENGTH: st.lens.focalLengthMm = g_value_get_double(value); break;
        case PROP_SENSOR_WIDTH: st.lens.sensorWidthMm = g_value_get_double(value); break;
        case PROP_FOV_FROM: st.lens.fovFrom = static_cast<defocus::Lens::FovFrom>(g_value_get_enum(value)); break;
        case PROP_MAX_COC: st.lens.maxCocPx = g_value_get_double(value); break;
        case PROP_COC_MODEL: st.lens.cocModel = static_cast<defocus::Lens::Model>(g_value_get_enum(value)); break;
        case PROP_NEAR: st.lens.nearM = g_value_get_double(value); break;
        case PROP_FAR: st.lens.farM = g_value_get_double(value); break;
        case PROP_QUALITY: st.quality.preset = static_cast<defocus::Quality::Preset>(g_value_get_enum(value)); break;
        case PROP_SAMPLES: {
            const int samples = g_value_get_int(value);
            st.quality.samples = samples == 0 ? std::nullopt : std::optional<int>(samples);
            break;
        }
        case PROP_HEXAGON: {
            const int v = g_value_get_enum(value);
            st.quality.hexagon = v == 0 ? std::nullopt
                                        : std::optional(v == 1 ? defocus::Quality::Hexagon::Rhombi
                                                               : defocus::Quality::Hexagon::McIntosh);
            break;
        }
        case PROP_PRECISION: {
            const int v = g_value_get_enum(value);
            st.quality.precision = v == 0 ? std::nullopt
                                          : std::optional(v == 1 ? defocus::Quality::Precision::F16
                                                                 : defocus::Quality::Precision::F32);
            break;
        }
        case PROP_RESOLUTION: {
            const int v = g_value_get_enum(value);
            st.quality.resolution = v == 0 ? std::nullopt
                                           : std::optional(v == 1 ? defocus::Quality::Resolution::Full
                                                                  : defocus::Quality::Resolution::Half);
            break;
        }
        case PROP_NEAR_FIELD:
            st.quality.nearField = g_value_get_boolean(value) != FALSE;
            s.nearFieldSet = true;
            break;
        case PROP_HIGHLIGHT_SPRITES: st.quality.highlightSprites = g_value_get_boolean(value) != FALSE; break;
        case PROP_HIGHLIGHT_GAIN: st.quality.highlightGain = g_value_get_double(value); break;
        case PROP_BLADES: st.lens.blades = g_value_get_int(value); break;
        case PROP_BLADE_ROTATION: st.lens.bladeRotationDeg = g_value_get_double(value); break;
        case PROP_APERTURE_RATIO: st.lens.apertureRatio = g_value_get_double(value); break;
        case PROP_DEPTH_SCALE: st.depthScale = g_value_get_double(value); break;
        case PROP_VIEW: st.view = static_cast<defocus::Settings::View>(g_value_get_enum(value)); break;
        case PROP_POST_TIMINGS: s.postTimings = g_value_get_boolean(value) != FALSE; break;
        default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec); return;
        }
        ++s.generation;
    }
    if (autofocusOff)
        g_object_notify(object, "autofocus");
}

void getProperty(GObject* object, guint id, GValue* value, GParamSpec* pspec)
{
    State& s = stateOf(object);
    std::lock_guard guard(s.lock);
    const defocus::Settings& st = s.settings;
    switch (id) {
    case PROP_FOCUS: g_value_set_double(value, st.lens.focusM); break;
    case PROP_AUTOFOCUS: g_value_set_boolean(value, st.autofocus.mode != defocus::AutofocusOptions::Mode::Off); break;
    case PROP_AUTOFOCUS_TIME_CONSTANT: g_value_set_double(value, st.autofocus.timeConstantS); break;
    case PROP_F_NUMBER: g_value_set_double(value, st.lens.fNumber); break;
    case PROP_FOCAL_LENGTH: g_value_set_double(value, st.lens.focalLengthMm); break;
    case PROP_SENSOR_WIDTH: g_value_set_double(value, st.lens.sensorWidthMm); break;
    case PROP_FOV_FROM: g_value_set_enum(value, static_cast<int>(st.lens.fovFrom)); break;
    case PROP_MAX_COC: g_value_set_double(value, st.lens.maxCocPx); break;
    case PROP_COC_MODEL: g_value_set_enum(value, static_cast<int>(st.lens.cocModel)); break;
    case PROP_NEAR: g_value_set_double(value, st.lens.nearM); break;
    case PROP_FAR: g_value_set_double(value, st.lens.farM); break;
    case PROP_QUALITY: g_value_set_enum(value, static_cast<int>(st.quality.preset)); break;
    case PROP_SAMPLES: g_value_set_int(value, st.quality.samples.value_or(0)); break;
    case PROP_HEXAGON:
        g_value_set_enum(value, !st.quality.hexagon ? 0 : *st.quality.hexagon == defocus::Quality::Hexagon::Rhombi ? 1 : 2);
        break;
    case PROP_PRECISION:
        g_value_set_enum(value,
                         !st.quality.precision ? 0 : *st.quality.precision == defocus::Quality::Precision::F16 ? 1 : 2);
        break;
    case PROP_RESOLUTION:
        g_value_set_enum(value, !st.quality.resolution                                       ? 0
                                : *st.quality.resolution == defocus::Quality::Resolution::Full ? 1
                                                                                               : 2);
        break;
    case PROP_NEAR_FIELD: g_value_set_boolean(value, st.quality.nearField.value_or(true)); break;
    case PROP_HIGHLIGHT_SPRITES: g_value_set_boolean(value, st.quality.highlightSprites); break;
    case PROP_HIGHLIGHT_GAIN: g_value_set_double(value, st.quality.highlightGain); break;
    case PROP_BLADES: g_value_set_int(value, st.lens.blades); break;
    case PROP_BLADE_ROTATION: g_value_set_double(value, st.lens.bladeRotationDeg); break;
    case PROP_APERTURE_RATIO: g_value_set_double(value, st.lens.apertureRatio); break;
    case PROP_DEPTH_SCALE: g_value_set_double(value, st.depthScale); break;
    case PROP_VIEW: g_value_set_enum(value, static_cast<int>(st.view)); break;
    case PROP_POST_TIMINGS: g_value_set_boolean(value, s.postTimings); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec); break;
    }
}

// ---- pads ----------------------------------------------------------------------------------------

GstAggregatorPad* createNewPad(GstAggregator* agg, GstPadTemplate* templ, const gchar*, const GstCaps*)
{
    State& s = stateOf(agg);
    const bool isColor = g_strcmp0(GST_PAD_TEMPLATE_NAME_TEMPLATE(templ), "color") == 0;
    GST_OBJECT_LOCK(agg);
    GstVideoAggregatorPad*& slot = isColor ? s.color : s.depth;
    if (slot) {
        GST_OBJECT_UNLOCK(agg);
        GST_WARNING_OBJECT(agg, "the %s pad exists already; there is one of each", isColor ? "color" : "depth");
        return nullptr;
    }
    const GType type = isColor ? GST_TYPE_VIDEO_AGGREGATOR_CONVERT_PAD : GST_TYPE_VIDEO_AGGREGATOR_PAD;
    auto* pad = GST_VIDEO_AGGREGATOR_PAD(g_object_new(type, "name", isColor ? "color" : "depth", "direction",
                                                      GST_PAD_SINK, "template", templ, nullptr));
    slot = pad;
    GST_OBJECT_UNLOCK(agg);
    return GST_AGGREGATOR_PAD(pad);
}

void releasePad(GstElement* element, GstPad* pad)
{
    State& s = stateOf(element);
    GST_OBJECT_LOCK(element);
    if (GST_VIDEO_AGGREGATOR_PAD(pad) == s.color)
        s.color = nullptr;
    if (GST_VIDEO_AGGREGATOR_PAD(pad) == s.depth)
        s.depth = nullptr;
    GST_OBJECT_UNLOCK(element);
    GST_ELEMENT_CLASS(gst_defocus_parent_class)->release_pad(element, pad);
}

/// The colour and depth pads, referenced (either may be null).
void pads(GstDefocus* self, GstVideoAggregatorPad*& color, GstVideoAggregatorPad*& depth)
{
    State& s = *self->state;
    GST_OBJECT_LOCK(self);
    color = s.color ? GST_VIDEO_AGGREGATOR_PAD(gst_object_ref(s.color)) : nullptr;
    depth = s.depth ? GST_VIDEO_AGGREGATOR_PAD(gst_object_ref(s.depth)) : nullptr;
    GST_OBJECT_UNLOCK(self);
}

// ---- GL memory -----------------------------------------------------------------------------------
//
// In a GL pipeline the element renders on the pipeline's GstGLContext, on that context's thread,
// with the library's Filter made for the caller's context (ContextOptions::callerContext). The
// display and context come as GStreamer's GL elements share them: a GstContext set on the element
// or found by a context query of the neighbours (gst_gl_ensure_element_data), the neighbours'
// context (gst_gl_query_local_gl_context), else one made on the display.

bool isGlCaps(const GstCaps* caps)
{
    return caps && gst_caps_get_size(caps) > 0 &&
           gst_caps_features_contains(gst_caps_get_features(caps, 0), GST_CAPS_FEATURE_MEMORY_GL_MEMORY);
}

/// False for a display GStreamer's GL library made but cannot use: none (no window system), or an
/// EGL default display that does not initialise (Mesa with no display and no /dev/dri).
bool usable(GstGLDisplay* display)
{
    const GstGLDisplayType type = gst_gl_display_get_handle_type(display);
    if (type == GST_GL_DISPLAY_TYPE_NONE)
        return false;
    if (type != GST_GL_DISPLAY_TYPE_EGL)
        return true;
    auto* egl = reinterpret_cast<EGLDisplay>(gst_gl_display_get_handle(display));
    return egl != EGL_NO_DISPLAY && eglInitialize(egl, nullptr, nullptr) == EGL_TRUE;
}

/// The pipeline's GL display (under s.glLock). Where GStreamer's GL library opens none of its own
/// that works (no window system, no EGL default display: a server with no display and no
/// /dev/dri), one on the EGL display the library renders on, offered to the neighbours
/// (have-context).
bool ensureDisplay(GstDefocus* self)
{
    State& s = *self->state;
    if (!gst_gl_ensure_element_data(self, &s.display, &s.otherContext))
        return false;
    if (!usable(s.display)) {
        try {
            GstGLDisplayEGL* headless = gst_gl_display_egl_new_with_egl_display(defocus::eglDisplay());
            if (!headless)
                return false;
            gst_object_unref(s.display);
            s.display = GST_GL_DISPLAY(headless);
            GST_INFO_OBJECT(self, "no window system: GL on the library's headless EGL display");
            gst_gl_element_propagate_display_context(GST_ELEMENT(self), s.display);
        } catch (const defocus::GlError& error) {
            GST_WARNING_OBJECT(self, "no headless EGL display either: %s", error.what());
            return false;
        }
    }
    gst_gl_display_filter_gl_api(s.display, GST_GL_API_OPENGL3);
    return true;
}

/// The GL path's filter destroyed on its context's thread (its GL objects are that context's).
void dropGlFilter(State& s)
{
    if (s.glFilter && s.glContext)
        gst_gl_context_thread_add(
            s.glContext, [](GstGLContext*, gpointer state) { static_cast<State*>(state)->glFilter.reset(); }, &s);
    s.glFilter.reset();
}

/// The display and the context the GL path renders on (under s.glLock): the neighbours' context,
/// else one made on the display. Posts the element's error where there is none, or it is not
/// OpenGL 4.5.
bool ensureGl(GstDefocus* self)
{
    State& s = *self->state;
    std::lock_guard guard(s.glLock);
    if (!ensureDisplay(self)) {
        GST_ELEMENT_ERROR(self, RESOURCE, NOT_FOUND, ("No OpenGL display for GL memory"), (nullptr));
        return false;
    }
    if (s.glContext && s.glContext->display == s.display)
        return true;
    GstGLContext* found = nullptr;
    if ((gst_gl_query_local_gl_context(GST_ELEMENT(self), GST_PAD_SRC, &found) ||
         gst_gl_query_local_gl_context(GST_ELEMENT(self), GST_PAD_SINK, &found)) &&
        found && found->display == s.display) {
        dropGlFilter(s);
        gst_clear_object(&s.glContext);
        s.glContext = found;
    } else {
        gst_clear_object(&found);
        dropGlFilter(s);
        GError* error = nullptr;
        GST_OBJECT_LOCK(s.display);
        do {
            gst_clear_object(&s.glContext);
            s.glContext = gst_gl_display_get_gl_context_for_thread(s.display, nullptr);
            if (!s.glContext && !gst_gl_display_create_context(s.display, s.otherContext, &s.glContext, &error))
                break;
        } while (!gst_gl_display_add_context(s.display, s.glContext));
        GST_OBJECT_UNLOCK(s.display);
        if (!s.glContext) {
            GST_ELEMENT_ERROR(self, RESOURCE, NOT_FOUND, ("No OpenGL context for GL memory"), ("%s",
                              error ? error->message : "unknown"));
            g_clear_error(&error);
            return false;
        }
    }
    if (!gst_gl_context_check_gl_version(s.glContext, GST_GL_API_OPENGL3, 4, 5)) {
        gint major = 0, minor = 0;
        gst_gl_context_get_gl_version(s.glContext, &major, &minor);
        GST_ELEMENT_ERROR(self, LIBRARY, INIT, ("No OpenGL 4.5 for the defocus filter"),
                          ("the pipeline's GL context is OpenGL %d.%d (core profile 4.5 needed)", major, minor));
        gst_clear_object(&s.glContext);
        return false;
    }
    return true;
}

/// Context queries of the neighbours: the display (made here where none was: the headless one),
/// the context and the application's context.
bool contextQuery(GstDefocus* self, GstQuery* query)
{
    State& s = *self->state;
    std::lock_guard guard(s.glLock);
    const gchar* type = nullptr;
    gst_query_parse_context_type(query, &type);
    if (g_strcmp0(type, GST_GL_DISPLAY_CONTEXT_TYPE) == 0 && !s.display)
        ensureDisplay(self);
    return gst_gl_handle_context_query(GST_ELEMENT(self), query, s.display, s.glContext, s.otherContext);
}

void setContext(GstElement* element, GstContext* context)
{
    State& s = stateOf(element);
    {
        std::lock_guard guard(s.glLock);
        gst_gl_handle_set_context(element, context, &s.display, &s.otherContext);
        if (s.display)
            gst_gl_display_filter_gl_api(s.display, GST_GL_API_OPENGL3);
    }
    GST_ELEMENT_CLASS(gst_defocus_parent_class)->set_context(element, context);
}

/// The GL path's filter destroyed on its context's thread, and the context let go.
void dropGl(State& s)
{
    std::lock_guard guard(s.glLock);
    dropGlFilter(s);
    gst_clear_object(&s.glContext);
}

/// Upstream's buffers in GL memory: a GL buffer pool on the context, and sync metas.
gboolean proposeAllocation(GstAggregator* agg, GstAggregatorPad* pad, GstQuery* decideQuery, GstQuery* query)
{
    GstCaps* caps = nullptr;
    gboolean needPool = FALSE;
    gst_query_parse_allocation(query, &caps, &needPool);
    if (!isGlCaps(caps))
        return GST_AGGREGATOR_CLASS(gst_defocus_parent_class)->propose_allocation(agg, pad, decideQuery, query);
    auto* self = GST_DEFOCUS(agg);
    State& s = *self->state;
    GstVideoInfo info;
    if (!gst_video_info_from_caps(&info, caps) || !ensureGl(self))
        return FALSE;
    std::lock_guard guard(s.glLock);
    if (needPool) {
        GstBufferPool* pool = gst_gl_buffer_pool_new(s.glContext);
        GstStructure* config = gst_buffer_pool_get_config(pool);
        gst_buffer_pool_config_set_params(config, caps, static_cast<guint>(info.size), 0, 0);
        gst_buffer_pool_config_add_option(config, GST_BUFFER_POOL_OPTION_GL_SYNC_META);
        if (!gst_buffer_pool_set_config(pool, config)) {
            gst_object_unref(pool);
            return FALSE;
        }
        gst_query_add_allocation_pool(query, pool, static_cast<guint>(info.size), 1, 0);
        gst_object_unref(pool);
    }
    gst_query_add_allocation_meta(query, GST_GL_SYNC_META_API_TYPE, nullptr);
    return TRUE;
}

/// Output in GL memory: a GL buffer pool on the context (downstream's, where it offers a GL one of
/// this context; a GL memory allocator it offers is used), its buffers with sync metas.
gboolean decideAllocation(GstAggregator* agg, GstQuery* query)
{
    GstCaps* caps = nullptr;
    gst_query_parse_allocation(query, &caps, nullptr);
    if (!isGlCaps(caps))
        return GST_AGGREGATOR_CLASS(gst_defocus_parent_class)->decide_allocation(agg, query);
    auto* self = GST_DEFOCUS(agg);
    State& s = *self->state;
    GstVideoInfo info;
    if (!gst_video_info_from_caps(&info, caps) || !ensureGl(self))
        return FALSE;
    std::lock_guard guard(s.glLock);
    GstBufferPool* pool = nullptr;
    guint size = static_cast<guint>(info.size), min = 0, max = 0;
    const bool fromQuery = gst_query_get_n_allocation_pools(query) > 0;
    if (fromQuery) {
        gst_query_parse_nth_allocation_pool(query, 0, &pool, &size, &min, &max);
        if (pool && (!GST_IS_GL_BUFFER_POOL(pool) || GST_GL_BUFFER_POOL(pool)->context != s.glContext))
            gst_clear_object(&pool);
        size = std::max(size, static_cast<guint>(info.size));
    }
    if (!pool)
        pool = gst_gl_buffer_pool_new(s.glContext);
    GstStructure* config = gst_buffer_pool_get_config(pool);
    gst_buffer_pool_config_set_params(config, caps, size, min, max);
    gst_buffer_pool_config_add_option(config, GST_BUFFER_POOL_OPTION_VIDEO_META);
    gst_buffer_pool_config_add_option(config, GST_BUFFER_POOL_OPTION_GL_SYNC_META);
    if (gst_query_get_n_allocation_params(query) > 0) {
        GstAllocator* allocator = nullptr;
        GstAllocationParams params;
        gst_query_parse_nth_allocation_param(query, 0, &allocator, &params);
        if (allocator && GST_IS_GL_MEMORY_ALLOCATOR(allocator))
            gst_buffer_pool_config_set_allocator(config, allocator, &params);
        gst_clear_object(&allocator);
    }
    if (!gst_buffer_pool_set_config(pool, config)) {
        GST_ELEMENT_ERROR(self, RESOURCE, SETTINGS, ("The GL buffer pool refused its configuration"), (nullptr));
        gst_object_unref(pool);
        return FALSE;
    }
    if (fromQuery)
        gst_query_set_nth_allocation_pool(query, 0, pool, size, min, max);
    else
        gst_query_add_allocation_pool(query, pool, size, min, max);
    gst_object_unref(pool);
    return TRUE;
}

// The base class offers a pad the output's caps; depth has caps of its own (GRAY16), whatever the
// output is.
gboolean sinkQuery(GstAggregator* agg, GstAggregatorPad* pad, GstQuery* query)
{
    if (GST_QUERY_TYPE(query) == GST_QUERY_CONTEXT && contextQuery(GST_DEFOCUS(agg), query))
        return TRUE;
    GST_OBJECT_LOCK(agg);
    const bool depth = GST_VIDEO_AGGREGATOR_PAD(pad) == stateOf(agg).depth;
    GST_OBJECT_UNLOCK(agg);
    if (depth && GST_QUERY_TYPE(query) == GST_QUERY_CAPS) {
        GstCaps* filter = nullptr;
        gst_query_parse_caps(query, &filter);
        GstCaps* caps = gst_pad_get_pad_template_caps(GST_PAD(pad));
        if (filter) {
            GstCaps* both = gst_caps_intersect_full(filter, caps, GST_CAPS_INTERSECT_FIRST);
            gst_caps_unref(caps);
            caps = both;
        }
        gst_query_set_caps_result(query, caps);
        gst_caps_unref(caps);
        return TRUE;
    }
    if (depth && GST_QUERY_TYPE(query) == GST_QUERY_ACCEPT_CAPS) {
        GstCaps* caps = nullptr;
        gst_query_parse_accept_caps(query, &caps);
        GstCaps* templ = gst_pad_get_pad_template_caps(GST_PAD(pad));
        gst_query_set_accept_caps_result(query, gst_caps_is_subset(caps, templ));
        gst_caps_unref(templ);
        return TRUE;
    }
    return GST_AGGREGATOR_CLASS(gst_defocus_parent_class)->sink_query(agg, pad, query);
}

gboolean srcQuery(GstAggregator* agg, GstQuery* query)
{
    if (GST_QUERY_TYPE(query) == GST_QUERY_CONTEXT && contextQuery(GST_DEFOCUS(agg), query))
        return TRUE;
    return GST_AGGREGATOR_CLASS(gst_defocus_parent_class)->src_query(agg, query);
}

// ---- caps ----------------------------------------------------------------------------------------

/// The output has the colour's size, frame rate (0/1, variable, where the colour's is) and pixel
/// aspect; its format is the colour's when that is one of the output formats, else what
/// downstream prefers of them.
GstFlowReturn updateSrcCaps(GstAggregator* agg, GstCaps* downstream, GstCaps** result)
{
    auto* self = GST_DEFOCUS(agg);
    GstVideoAggregatorPad *color = nullptr, *depth = nullptr;
    pads(self, color, depth);
    if (depth)
        gst_object_unref(depth);
    if (!color)
        return GST_AGGREGATOR_FLOW_NEED_DATA;
    GST_OBJECT_LOCK(self);
    const GstVideoInfo info = color->info;
    GST_OBJECT_UNLOCK(self);
    GstCaps* colorCaps = gst_pad_get_current_caps(GST_PAD(color));
    const bool gl = isGlCaps(colorCaps);
    gst_clear_caps(&colorCaps);
    gst_object_unref(color);
    if (!info.finfo || GST_VIDEO_INFO_FORMAT(&info) == GST_VIDEO_FORMAT_UNKNOWN)
        return GST_AGGREGATOR_FLOW_NEED_DATA;

    GstCaps* shape = gst_caps_new_simple("video/x-raw", "width", G_TYPE_INT, info.width, "height", G_TYPE_INT,
                                         info.height, "pixel-aspect-ratio", GST_TYPE_FRACTION, info.par_n,
                                         info.par_d, nullptr);
    // The output's memory is the colour's: GL memory stays on the GPU, system memory in RAM.
    if (gl)
        gst_caps_set_features(shape, 0, gst_caps_features_new(GST_CAPS_FEATURE_MEMORY_GL_MEMORY, nullptr));
    // The colour's rate; 0/1 (variable: each frame has its own duration, a still image) stays so.
    gst_caps_set_simple(shape, "framerate", GST_TYPE_FRACTION, info.fps_n, info.fps_n > 0 ? info.fps_d : 1, nullptr);
    GstCaps* possible = gst_caps_intersect(downstream, shape);
    gst_caps_unref(shape);

    GstCaps* same = gst_caps_copy(possible);
    gst_caps_set_simple(same, "format", G_TYPE_STRING, gst_video_format_to_string(GST_VIDEO_INFO_FORMAT(&info)),
                        nullptr);
    GstCaps* preferred = gst_caps_intersect(same, possible);
    gst_caps_unref(same);
    *result = gst_caps_merge(preferred, possible);
    GST_DEBUG_OBJECT(self, "output caps %" GST_PTR_FORMAT, static_cast<void*>(*result));
    return GST_FLOW_OK;
}

/// The output's caps taken: the base class' work (GstVideoAggregator's, which divides by the
/// frame rate and so cannot take a variable one), done here. Latency: one frame of the output's
/// rate (a live colour frame waits that long for its depth); none at a variable rate.
gboolean negotiatedSrcCaps(GstAggregator* agg, GstCaps* caps)
{
    auto* self = GST_DEFOCUS(agg);
    GstVideoInfo info;
    if (!gst_video_info_from_caps(&info, caps))
        return FALSE;
    GST_OBJECT_LOCK(agg);
    GST_VIDEO_AGGREGATOR(agg)->info = info;
    GST_OBJECT_UNLOCK(agg);
    self->state->glOutput = isGlCaps(caps);
    GstVideoAggregatorPad *color = nullptr, *depth = nullptr;
    pads(self, color, depth);
    if (color) {
        // The colour pad converts to the new output format from its next frame on.
        gst_video_aggregator_convert_pad_update_conversion_info(GST_VIDEO_AGGREGATOR_CONVERT_PAD(color));
        gst_object_unref(color);
    }
    if (depth)
        gst_object_unref(depth);
    gst_aggregator_set_src_caps(agg, caps);
    const GstClockTime frame =
        info.fps_n > 0 ? gst_util_uint64_scale_int(GST_SECOND, info.fps_d, info.fps_n) : GstClockTime{0};
    gst_aggregator_set_latency(agg, frame, frame);
    return TRUE;
}

/// New caps on a pad that has some: the base class would hold them back until its own output grid
/// takes the next buffer, which this element does not use. Serialized events reach the element
/// in order with the buffers, so the next buffer is the first in the new caps: take them now.
gboolean sinkEvent(GstAggregator* agg, GstAggregatorPad* pad, GstEvent* event)
{
    GstVideoInfo info;
    bool newCaps = false;
    if (GST_EVENT_TYPE(event) == GST_EVENT_CAPS) {
        GstCaps* caps = nullptr;
        gst_event_parse_caps(event, &caps);
        newCaps = gst_video_info_from_caps(&info, caps);
    }
    const gboolean ok = GST_AGGREGATOR_CLASS(gst_defocus_parent_class)->sink_event(agg, pad, event);
    if (ok && newCaps) {
        auto* vpad = GST_VIDEO_AGGREGATOR_PAD(pad);
        GST_OBJECT_LOCK(agg);
        const bool changed = !gst_video_info_is_equal(&vpad->info, &info);
        vpad->info = info;
        GST_OBJECT_UNLOCK(agg);
        if (changed) {
            if (GST_IS_VIDEO_AGGREGATOR_CONVERT_PAD(pad))
                gst_video_aggregator_convert_pad_update_conversion_info(GST_VIDEO_AGGREGATOR_CONVERT_PAD(pad));
            gst_pad_mark_reconfigure(agg->srcpad);
        }
    }
    return ok;
}

GstCaps* fixateSrcCaps(GstAggregator*, GstCaps* caps)
{
    caps = gst_caps_make_writable(caps);
    GstStructure* s = gst_caps_get_structure(caps, 0);
    if (gst_structure_has_field(s, "pixel-aspect-ratio"))
        gst_structure_fixate_field_nearest_fraction(s, "pixel-aspect-ratio", 1, 1);
    return gst_caps_fixate(caps);
}

/// A view of `frame`'s first plane as a cv::Mat (no copy).
cv::Mat wrap(GstVideoFrame* frame, int type)
{
    return cv::Mat(GST_VIDEO_FRAME_HEIGHT(frame), GST_VIDEO_FRAME_WIDTH(frame), type,
                   GST_VIDEO_FRAME_PLANE_DATA(frame, 0), static_cast<size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(frame, 0)));
}

/// The Y'CbCr matrix and range of `info` where the filter takes its frames as they are (I420,
/// NV12, or YUY2 of an even width, in BT.601 or BT.709); nullopt for every other format, which
/// the colour pad converts.
std::optional<defocus::YuvImage> yuvLayout(const GstVideoInfo& info)
{
    defocus::YuvImage yuv;
    switch (GST_VIDEO_INFO_FORMAT(&info)) {
    case GST_VIDEO_FORMAT_I420: yuv.layout = defocus::YuvImage::Layout::I420; break;
    case GST_VIDEO_FORMAT_NV12: yuv.layout = defocus::YuvImage::Layout::Nv12; break;
    case GST_VIDEO_FORMAT_YUY2:
        if (GST_VIDEO_INFO_WIDTH(&info) % 2 != 0)
            return std::nullopt; // the last pixel's Cr lies in the row's padding
        yuv.layout = defocus::YuvImage::Layout::Yuyv;
        break;
    default: return std::nullopt;
    }
    switch (info.colorimetry.matrix) {
    case GST_VIDEO_COLOR_MATRIX_BT601: yuv.matrix = defocus::YuvImage::Matrix::Bt601; break;
    case GST_VIDEO_COLOR_MATRIX_BT709: yuv.matrix = defocus::YuvImage::Matrix::Bt709; break;
    default: return std::nullopt; // BT.2020, SMPTE 240M, ...: GStreamer's converter knows them
    }
    yuv.range = info.colorimetry.range == GST_VIDEO_COLOR_RANGE_0_255 ? defocus::YuvImage::Range::Full
                                                                      : defocus::YuvImage::Range::Limited;
    return yuv;
}

/// `frame` (I420, NV12 or YUY2, yuvLayout() of its info) as the filter's YuvImage: its planes, no
/// copy.
defocus::YuvImage toYuv(GstVideoFrame* frame)
{
    defocus::YuvImage yuv = *yuvLayout(frame->info);
    const int width = GST_VIDEO_FRAME_WIDTH(frame), height = GST_VIDEO_FRAME_HEIGHT(frame);
    const cv::Size half((width + 1) / 2, (height + 1) / 2);
    const auto plane = [&](guint i, cv::Size size, int type) {
        return cv::Mat(size, type, GST_VIDEO_FRAME_PLANE_DATA(frame, i),
                       static_cast<size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(frame, i)));
    };
    if (yuv.layout == defocus::YuvImage::Layout::Yuyv) {
        yuv.y = plane(0, {width, height}, CV_8UC2);
        return yuv;
    }
    yuv.y = plane(0, {width, height}, CV_8UC1);
    if (yuv.layout == defocus::YuvImage::Layout::Nv12) {
        yuv.u = plane(1, half, CV_8UC2);
    } else {
        yuv.u = plane(1, half, CV_8UC1);
        yuv.v = plane(2, half, CV_8UC1);
    }
    return yuv;
}

/// `color` (the output's format, converted by the colour pad) as the filter's BGR or BGRx.
cv::Mat toFilter(GstVideoFrame* color)
{
    cv::Mat out;
    switch (GST_VIDEO_FRAME_FORMAT(color)) {
    case GST_VIDEO_FORMAT_BGRx:
    case GST_VIDEO_FORMAT_BGRA: return wrap(color, CV_8UC4);
    case GST_VIDEO_FORMAT_BGR: return wrap(color, CV_8UC3);
    case GST_VIDEO_FORMAT_RGBx:
    case GST_VIDEO_FORMAT_RGBA: cv::cvtColor(wrap(color, CV_8UC4), out, cv::COLOR_RGBA2BGR); return out;
    case GST_VIDEO_FORMAT_RGB: cv::cvtColor(wrap(color, CV_8UC3), out, cv::COLOR_RGB2BGR); return out;
    default: return out;
    }
}

/// The filter's result into `frame`, in its format; alpha (or x) is opaque. BGRx and BGRA come
/// as the filter's BGRA (Settings::Output::Srgb8Bgra) and are copied; the others as BGR.
void fromFilter(const cv::Mat& bgr, GstVideoFrame* frame)
{
    // BGRx has three components but four bytes a pixel.
    cv::Mat out = wrap(frame, GST_VIDEO_FRAME_COMP_PSTRIDE(frame, 0) == 4 ? CV_8UC4 : CV_8UC3);
    if (bgr.type() == CV_8UC4) {
        bgr.copyTo(out);
        return;
    }
    switch (GST_VIDEO_FRAME_FORMAT(frame)) {
    case GST_VIDEO_FORMAT_BGRx:
    case GST_VIDEO_FORMAT_BGRA: cv::cvtColor(bgr, out, cv::COLOR_BGR2BGRA); break;
    case GST_VIDEO_FORMAT_RGBx:
    case GST_VIDEO_FORMAT_RGBA: cv::cvtColor(bgr, out, cv::COLOR_BGR2RGBA); break;
    case GST_VIDEO_FORMAT_RGB: cv::cvtColor(bgr, out, cv::COLOR_BGR2RGB); break;
    default: bgr.copyTo(out); break;
    }
}

/// `depth` as CV_16UC1 in the host's byte order.
cv::Mat depthOf(GstVideoFrame* depth)
{
    cv::Mat raw = wrap(depth, CV_16UC1);
    const bool swap = (GST_VIDEO_FRAME_FORMAT(depth) == GST_VIDEO_FORMAT_GRAY16_BE) != (G_BYTE_ORDER == G_BIG_ENDIAN);
    if (!swap)
        return raw;
    cv::Mat native(raw.size(), CV_16UC1);
    for (int y = 0; y < raw.rows; ++y) {
        const auto* in = raw.ptr<guint16>(y);
        auto* out = native.ptr<guint16>(y);
        for (int x = 0; x < raw.cols; ++x)
            out[x] = GUINT16_SWAP_LE_BE(in[x]);
    }
    return native;
}

void postTimings(GstDefocus* self, const defocus::FrameReport& report, GstClockTime pts)
{
    GstStructure* gpu = gst_structure_new_empty("gpu-ms");
    for (const auto& pass : report.timings.gpu)
        gst_structure_set(gpu, pass.name.c_str(), G_TYPE_DOUBLE, pass.ms, nullptr);
    GstStructure* s = gst_structure_new(
        "defocus-timings", "frame", G_TYPE_UINT64, static_cast<guint64>(report.index), "timestamp", G_TYPE_UINT64,
        static_cast<guint64>(pts), "total-ms", G_TYPE_DOUBLE, report.timings.totalMs, "depth-prep-ms", G_TYPE_DOUBLE,
        report.timings.depthPrepMs, "analysis-ms", G_TYPE_DOUBLE, report.timings.analysisMs, "upload-ms",
        G_TYPE_DOUBLE, report.timings.uploadMs, "render-ms", G_TYPE_DOUBLE, report.timings.renderMs, "readback-ms",
        G_TYPE_DOUBLE, report.timings.readbackMs, "gpu-frame", G_TYPE_UINT64,
        static_cast<guint64>(report.timings.gpuFrame), "gpu-ms", GST_TYPE_STRUCTURE, gpu, "focus", G_TYPE_DOUBLE,
        report.focusM, "all-in-focus", G_TYPE_BOOLEAN, report.plan.allInFocus, "tiles", G_TYPE_UINT,
        static_cast<guint>(report.plan.tiles), "blur-tiles", G_TYPE_UINT, static_cast<guint>(report.plan.blurTiles),
        "plan", G_TYPE_STRING, report.plan.explain.c_str(), nullptr);
    gst_structure_free(gpu);
    gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), s));
}

/// The properties as the filter takes them: out-of-range combinations (a focus nearer than the
/// focal length, near beyond the focus) are clamped, each posted once as a warning.
defocus::Settings currentSettings(GstDefocus* self, bool& changed, bool& post)
{
    State& s = *self->state;
    defocus::Settings settings;
    {
        std::lock_guard guard(s.lock);
        settings = s.settings;
        if (!s.nearFieldSet)
            settings.quality.nearField.reset();
        changed = s.generation != s.applied;
        s.applied = s.generation;
        post = s.postTimings;
    }
    if (changed)
        for (const std::string& problem : defocus::check(settings, true))
            if (s.warned.insert(problem).second)
                GST_ELEMENT_WARNING(self, LIBRARY, SETTINGS, ("%s", problem.c_str()),
                                    ("clamped to the nearest allowed value"));
    return settings;
}

// ---- streaming -------------------------------------------------------------------------------------
//
// One output frame per colour frame, with its timestamp and duration: the element drives the
// base class' aggregate() itself instead of GstVideoAggregator's output grid, which runs at one
// frame rate and repeats (or drops) colour frames whose timestamps do not fall on it (recorded
// RGB-D clips have gaps where the sensor dropped frames). The colour pad still converts the colour
// to the output's format, and the caps are still negotiated by the base class.

/// Running time of `buffer`'s start in `pad`'s segment; NONE without a timestamp.
GstClockTime runningTimeOf(GstAggregatorPad* pad, GstBuffer* buffer)
{
    GST_OBJECT_LOCK(pad);
    const GstClockTime t = gst_segment_to_running_time(&pad->segment, GST_FORMAT_TIME, GST_BUFFER_PTS(buffer));
    GST_OBJECT_UNLOCK(pad);
    return t;
}

/// Moves the output position on by `duration` (a live stream with no colour frame in time), so
/// that the base class' next deadline is one frame later.
void advance(GstAggregator* agg, GstClockTime duration)
{
    GST_OBJECT_LOCK(agg);
    GstSegment& segment = GST_AGGREGATOR_PAD(agg->srcpad)->segment;
    if (!GST_CLOCK_TIME_IS_VALID(segment.position) || segment.position < segment.start)
        segment.position = segment.start;
    segment.position += duration;
    GST_OBJECT_UNLOCK(agg);
}

/// The colour frame's duration: its own, else one frame of the output's rate, else NONE
/// (variable rate without durations).
GstClockTime durationOf(GstVideoAggregator* vagg, GstBuffer* color)
{
    if (GST_BUFFER_DURATION_IS_VALID(color))
        return GST_BUFFER_DURATION(color);
    if (GST_VIDEO_INFO_FPS_N(&vagg->info) > 0)
        return gst_util_uint64_scale_int(GST_SECOND, GST_VIDEO_INFO_FPS_D(&vagg->info),
                                         GST_VIDEO_INFO_FPS_N(&vagg->info));
    return GST_CLOCK_TIME_NONE;
}

/// What a frame is filtered with: the properties at its stream time (keyframed ones through
/// GstController) and its running time in seconds (the autofocus' clock).
struct FrameSetup {
    defocus::Settings settings;
    bool changed = false; ///< since the last frame
    bool post = false;    ///< post-timings
    double seconds = 0.0;
};

FrameSetup setUpFrame(GstDefocus* self, GstClockTime pts)
{
    GstAggregator* agg = GST_AGGREGATOR(self);
    GST_OBJECT_LOCK(agg->srcpad);
    const GstSegment segment = GST_AGGREGATOR_PAD(agg->srcpad)->segment;
    GST_OBJECT_UNLOCK(agg->srcpad);
    const GstClockTime streamTime = gst_segment_to_stream_time(&segment, GST_FORMAT_TIME, pts);
    if (GST_CLOCK_TIME_IS_VALID(streamTime))
        gst_object_sync_values(GST_OBJECT(self), streamTime);
    FrameSetup setup;
    setup.settings = currentSettings(self, setup.changed, setup.post);
    const GstClockTime running = gst_segment_to_running_time(&segment, GST_FORMAT_TIME, pts);
    setup.seconds = GST_CLOCK_TIME_IS_VALID(running) ? static_cast<double>(running) / GST_SECOND : 0.0;
    return setup;
}

/// The frames in flight dropped: the filter's (a new stream) and the element's mappings of them.
void dropInFlight(State& s)
{
    if (s.filter)
        s.filter->reset();
    for (InFlight& frame : s.inFlight)
        unmap(frame);
    s.inFlight.clear();
}

/// Runs `call`, a call of the filter for `frame`; an error of the library or of OpenCV becomes
/// the element's, and the frame's mappings are let go.
template <typename Call>
GstFlowReturn guarded(GstDefocus* self, InFlight& frame, Call&& call)
{
    try {
        call();
        return GST_FLOW_OK;
    } catch (const defocus::Error& error) {
        GST_ELEMENT_ERROR(self, STREAM, FORMAT, ("%s", error.what()), (nullptr));
    } catch (const cv::Exception& error) {
        GST_ELEMENT_ERROR(self, STREAM, FAILED, ("%s", error.what()), (nullptr));
    }
    unmap(frame);
    return GST_FLOW_ERROR;
}

/// Submits `color` (the output's format, or I420, NV12 or YUY2 as it came) with `depth` to the filter,
/// to come out with `pts` and `duration`; the frame joins the frames in flight.
GstFlowReturn submit(GstDefocus* self, GstVideoFrame* color, GstBuffer* depth, GstVideoInfo* depthInfo,
                     GstClockTime pts, GstClockTime duration)
{
    State& s = *self->state;
    const FrameSetup setup = setUpFrame(self, pts);
    defocus::Settings settings = setup.settings;
    // BGRx and BGRA come back as they go out, four bytes a pixel: no conversion on either side.
    GST_OBJECT_LOCK(self);
    const GstVideoFormat format = GST_VIDEO_INFO_FORMAT(&GST_VIDEO_AGGREGATOR(self)->info);
    GST_OBJECT_UNLOCK(self);
    settings.output = format == GST_VIDEO_FORMAT_BGRx || format == GST_VIDEO_FORMAT_BGRA
                          ? defocus::Settings::Output::Srgb8Bgra
                          : defocus::Settings::Output::Srgb8;
    const defocus::gst::LibraryCall call(GST_ELEMENT(self));

    try {
        if (!s.filter) {
            // Made here, on the streaming thread, the first time a frame needs it.
            s.filter = std::make_unique<defocus::Filter>(settings);
            GST_INFO_OBJECT(self, "filtering on %s", s.filter->renderer().c_str());
        } else if (setup.changed || s.filter->settings().output != settings.output) {
            s.filter->setSettings(settings);
        }
    } catch (const defocus::GlError& error) {
        GST_ELEMENT_ERROR(self, LIBRARY, INIT, ("No OpenGL 4.5 for the defocus filter"), ("%s", error.what()));
        return GST_FLOW_ERROR;
    } catch (const defocus::Error& error) {
        GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, ("%s", error.what()), (nullptr));
        return GST_FLOW_ERROR;
    }
    // The element's own mappings: the colour pad's is cleaned when this returns, and the depth
    // frame may be replaced before the frame is received.
    InFlight frame;
    frame.pts = pts;
    frame.duration = duration;
    frame.post = setup.post;
    if (!gst_video_frame_map(&frame.color, &color->info, color->buffer, GST_MAP_READ) ||
        !gst_video_frame_map(&frame.depth, depthInfo, depth, GST_MAP_READ)) {
        unmap(frame);
        GST_ELEMENT_ERROR(self, STREAM, FAILED, ("A colour or depth frame could not be mapped"), (nullptr));
        return GST_FLOW_ERROR;
    }
    const GstFlowReturn ret = guarded(self, frame, [&] {
        if (yuvLayout(frame.color.info))
            s.filter->submit(toYuv(&frame.color), depthOf(&frame.depth), setup.seconds);
        else
            s.filter->submit(toFilter(&frame.color), depthOf(&frame.depth), setup.seconds);
    });
    if (ret == GST_FLOW_OK)
        s.inFlight.push_back(frame);
    return ret;
}

/// Receives the oldest frame in flight from the filter and pushes it downstream with its
/// timestamp and duration.
GstFlowReturn pushOldest(GstDefocus* self)
{
    State& s = *self->state;
    auto* agg = GST_AGGREGATOR(self);
    auto* vagg = GST_VIDEO_AGGREGATOR(self);
    InFlight frame = s.inFlight.front();
    s.inFlight.pop_front();
    cv::Mat result;
    const GstFlowReturn received = guarded(self, frame, [&] {
        const defocus::gst::LibraryCall call(GST_ELEMENT(self));
        result = s.filter->receive().value();
        if (frame.post)
            postTimings(self, s.filter->lastFrame(), frame.pts);
    });
    if (received != GST_FLOW_OK)
        return received;
    unmap(frame);

    GstBuffer* outbuf = nullptr;
    GstFlowReturn ret = GST_VIDEO_AGGREGATOR_CLASS(gst_defocus_parent_class)->create_output_buffer(vagg, &outbuf);
    if (ret != GST_FLOW_OK || !outbuf)
        return ret;
    GST_BUFFER_PTS(outbuf) = frame.pts;
    GST_BUFFER_DTS(outbuf) = GST_CLOCK_TIME_NONE;
    GST_BUFFER_DURATION(outbuf) = frame.duration;
    GstVideoFrame out;
    if (!gst_video_frame_map(&out, &vagg->info, outbuf, GST_MAP_WRITE)) {
        gst_buffer_unref(outbuf);
        GST_ELEMENT_ERROR(self, RESOURCE, WRITE, ("The output buffer could not be mapped"), (nullptr));
        return GST_FLOW_ERROR;
    }
    fromFilter(result, &out);
    gst_video_frame_unmap(&out);
    return gst_aggregator_finish_buffer(agg, outbuf);
}

/// Pushes the frames in flight out: all of them, or (`all` false) the oldest until fewer than
/// the filter's kFramesInFlight are left.
GstFlowReturn pushReceived(GstDefocus* self, bool all)
{
    State& s = *self->state;
    GstFlowReturn ret = GST_FLOW_OK;
    while (ret == GST_FLOW_OK && !s.inFlight.empty() &&
           (all || s.inFlight.size() >= defocus::Filter::kFramesInFlight))
        ret = pushOldest(self);
    if (!s.inFlight.empty())
        GST_LOG_OBJECT(self, "%zu frame(s) in flight", s.inFlight.size());
    // The streaming thread may be another one after a seek or a pause: let it take the context.
    if (s.filter)
        s.filter->release();
    return ret;
}

/// One frame of the GL path, run on the GL context's thread (gst_gl_context_thread_add).
struct GlJob {
    GstDefocus* self = nullptr;
    const FrameSetup* setup = nullptr;
    defocus::GlFrame frame;
    bool noGl = false;       ///< the filter could not be made on the context
    std::string error;       ///< empty: done
    defocus::FrameReport report;
};

void runGlJob(GstGLContext*, gpointer data)
{
    GlJob& job = *static_cast<GlJob*>(data);
    State& s = *job.self->state;
    const defocus::gst::LibraryCall call(GST_ELEMENT(job.self));
    try {
        if (!s.glFilter) {
            defocus::ContextOptions options;
            options.callerContext = true;
            try {
                s.glFilter = std::make_unique<defocus::Filter>(job.setup->settings, options);
            } catch (const defocus::GlError&) {
                job.noGl = true;
                throw;
            }
            GST_INFO_OBJECT(job.self, "filtering GL memory on %s", s.glFilter->renderer().c_str());
        } else if (job.setup->changed) {
            s.glFilter->setSettings(job.setup->settings);
        }
        if (s.resetPending.exchange(false))
            s.glFilter->reset();
        s.glFilter->processTextures(job.frame, job.setup->seconds);
        job.report = s.glFilter->lastFrame();
    } catch (const defocus::Error& error) {
        job.error = error.what();
    } catch (const cv::Exception& error) {
        job.error = error.what();
    }
}

/// `access` for GL (GST_MAP_GL: the texture, no CPU copy).
GstMapFlags forGl(GstMapFlags access)
{
    const guint flags = static_cast<guint>(access) | static_cast<guint>(GST_MAP_GL);
    return static_cast<GstMapFlags>(flags);
}

/// The texture of a frame mapped for GL (GST_MAP_GL: no CPU copy).
guint textureOf(GstVideoFrame* frame)
{
    return *static_cast<guint*>(GST_VIDEO_FRAME_PLANE_DATA(frame, 0));
}

/// GL memory in and out: `color` and `depth` (their pads' infos) filtered into `outbuf`'s texture
/// on the context's thread, after upstream's sync points, with a sync point of its own.
GstFlowReturn renderGl(GstDefocus* self, GstBuffer* outbuf, GstBuffer* color, GstVideoInfo* colorInfo,
                       GstBuffer* depth, GstVideoInfo* depthInfo)
{
    State& s = *self->state;
    std::lock_guard guard(s.glLock);
    if (!s.glContext && !ensureGl(self))
        return GST_FLOW_ERROR;
    for (GstBuffer* buffer : {color, depth})
        if (gst_buffer_n_memory(buffer) == 0 || !gst_is_gl_memory(gst_buffer_peek_memory(buffer, 0))) {
            GST_ELEMENT_ERROR(self, STREAM, FORMAT, ("GL memory out needs the colour and the depth in GL memory"),
                              ("put glupload before the %s pad", buffer == color ? "color" : "depth"));
            return GST_FLOW_ERROR;
        }
    const FrameSetup setup = setUpFrame(self, GST_BUFFER_PTS(outbuf));
    for (GstBuffer* buffer : {color, depth})
        if (GstGLSyncMeta* sync = gst_buffer_get_gl_sync_meta(buffer))
            gst_gl_sync_meta_wait(sync, s.glContext);

    GstVideoFrame in{}, far{}, out{};
    const GstMapFlags glRead = forGl(GST_MAP_READ), glWrite = forGl(GST_MAP_WRITE);
    const bool mapped = gst_video_frame_map(&in, colorInfo, color, glRead);
    const bool depthMapped = gst_video_frame_map(&far, depthInfo, depth, glRead);
    const bool outMapped = gst_video_frame_map(&out, &GST_VIDEO_AGGREGATOR(self)->info, outbuf, glWrite);
    GstFlowReturn ret = GST_FLOW_OK;
    if (!mapped || !depthMapped || !outMapped) {
        GST_ELEMENT_ERROR(self, STREAM, FAILED, ("A GL frame could not be mapped for GL"), (nullptr));
        ret = GST_FLOW_ERROR;
    } else {
        const auto order = [](GstVideoFormat format) {
            return format == GST_VIDEO_FORMAT_BGRA || format == GST_VIDEO_FORMAT_BGRx ? defocus::GlFrame::Order::Bgra
                                                                                      : defocus::GlFrame::Order::Rgba;
        };
        GlJob job;
        job.self = self;
        job.setup = &setup;
        job.frame.color = textureOf(&in);
        job.frame.colorOrder = order(GST_VIDEO_FRAME_FORMAT(&in));
        job.frame.depth = textureOf(&far);
        job.frame.depthFormat = defocus::GlFrame::DepthFormat::Rg8Le;
        job.frame.output = textureOf(&out);
        job.frame.outputOrder = order(GST_VIDEO_FRAME_FORMAT(&out));
        job.frame.width = GST_VIDEO_FRAME_WIDTH(&in);
        job.frame.height = GST_VIDEO_FRAME_HEIGHT(&in);
        gst_gl_context_thread_add(s.glContext, runGlJob, &job);
        if (job.noGl) {
            GST_ELEMENT_ERROR(self, LIBRARY, INIT, ("No OpenGL 4.5 for the defocus filter"), ("%s", job.error.c_str()));
            ret = GST_FLOW_ERROR;
        } else if (!job.error.empty()) {
            GST_ELEMENT_ERROR(self, STREAM, FORMAT, ("%s", job.error.c_str()), (nullptr));
            ret = GST_FLOW_ERROR;
        } else {
            GstGLSyncMeta* sync = gst_buffer_get_gl_sync_meta(outbuf);
            if (!sync)
                sync = gst_buffer_add_gl_sync_meta(s.glContext, outbuf);
            gst_gl_sync_meta_set_sync_point(sync, s.glContext);
            if (setup.post)
                postTimings(self, job.report, GST_BUFFER_PTS(outbuf));
        }
    }
    if (outMapped)
        gst_video_frame_unmap(&out);
    if (depthMapped)
        gst_video_frame_unmap(&far);
    if (mapped)
        gst_video_frame_unmap(&in);
    return ret;
}

/// Brings the depth frame up to the colour frame at running time `colorTime`: the last depth
/// frame that starts at or before it (the first one for colour that starts before any depth).
/// False: a depth frame queued later may still start at or before it (wait for more data).
bool catchUpDepth(State& s, GstAggregatorPad* depth, GstClockTime colorTime)
{
    if (!GST_CLOCK_TIME_IS_VALID(colorTime)) {
        // Colour without timestamps: paired in order, the next depth frame while depth lasts.
        if (GstBuffer* next = gst_aggregator_pad_pop_buffer(depth)) {
            gst_buffer_replace(&s.depthFrame, next);
            s.depthEnd = GST_CLOCK_TIME_NONE;
            gst_buffer_unref(next);
        }
        return s.depthFrame || gst_aggregator_pad_is_eos(depth);
    }
    while (GstBuffer* next = gst_aggregator_pad_peek_buffer(depth)) {
        const GstClockTime start = runningTimeOf(depth, next);
        if (s.depthFrame && GST_CLOCK_TIME_IS_VALID(start) && start > colorTime) {
            gst_buffer_unref(next);
            return true;
        }
        gst_buffer_replace(&s.depthFrame, next);
        s.depthEnd = GST_CLOCK_TIME_IS_VALID(start) && GST_BUFFER_DURATION_IS_VALID(next)
                         ? start + GST_BUFFER_DURATION(next)
                         : GST_CLOCK_TIME_NONE;
        gst_buffer_unref(next);
        gst_aggregator_pad_drop_buffer(depth);
    }
    // Nothing queued: known when the depth has ended or the current frame lasts past the colour's.
    return gst_aggregator_pad_is_eos(depth) || (GST_CLOCK_TIME_IS_VALID(s.depthEnd) && s.depthEnd > colorTime);
}

/// The element's GstAggregator::aggregate: the next colour frame, paired with the depth frame
/// current at its running time, filtered and pushed with the colour's timestamp and duration.
/// Not live, the base class calls it once both pads have data or have ended; live, also at each
/// deadline (timeout), where a colour frame whose depth is late is dropped rather than waited for.
GstFlowReturn aggregate(GstAggregator* agg, gboolean timeout)
{
    auto* self = GST_DEFOCUS(agg);
    auto* vagg = GST_VIDEO_AGGREGATOR(agg);
    State& s = *self->state;
    GstVideoAggregatorPad *colorPad = nullptr, *depthPad = nullptr;
    pads(self, colorPad, depthPad);
    const auto unrefPads = [&] {
        if (colorPad)
            gst_object_unref(colorPad);
        if (depthPad)
            gst_object_unref(depthPad);
    };
    if (!depthPad || !colorPad) {
        if (!depthPad)
            GST_ELEMENT_ERROR(self, STREAM, FAILED, ("No depth stream: link one to the defocus element's 'depth' pad"),
                              ("defocus needs GRAY16 depth, e.g. '... ! pngdec ! imagefreeze ! d.depth' for one image"));
        else
            GST_ELEMENT_ERROR(self, STREAM, FAILED, ("No colour stream: link one to the defocus element's 'color' pad"),
                              (nullptr));
        unrefPads();
        return GST_FLOW_ERROR;
    }
    auto* color = GST_AGGREGATOR_PAD(colorPad);
    auto* depth = GST_AGGREGATOR_PAD(depthPad);
    if (s.depthStale.exchange(false))
        gst_clear_buffer(&s.depthFrame); // a flush: depth from before it is not this stream's
    // A flush: the frames in flight from before it are not pushed, and the next frame starts a
    // new stream (the GL path resets its own filter on its thread).
    if (!s.glOutput && s.resetPending.exchange(false))
        dropInFlight(s);

    GstBuffer* colorBuffer = gst_aggregator_pad_peek_buffer(color);
    if (!colorBuffer) {
        // The colour has ended (depth may go on, e.g. from imagefreeze): so has the output,
        // after the frames still in flight.
        const bool ended = gst_aggregator_pad_is_eos(color);
        if (!ended && timeout)
            advance(agg, s.lastDuration);
        unrefPads();
        const GstFlowReturn pushed = pushReceived(self, true);
        if (pushed != GST_FLOW_OK)
            return pushed;
        return ended ? GST_FLOW_EOS : GST_AGGREGATOR_FLOW_NEED_DATA;
    }
    if (GST_VIDEO_INFO_FORMAT(&vagg->info) == GST_VIDEO_FORMAT_UNKNOWN) {
        gst_buffer_unref(colorBuffer); // the output's caps come first (negotiated by the base class)
        unrefPads();
        return GST_AGGREGATOR_FLOW_NEED_DATA;
    }
    const GstClockTime colorTime = runningTimeOf(color, colorBuffer);
    const GstClockTime duration = durationOf(vagg, colorBuffer);
    if (!catchUpDepth(s, depth, colorTime) && !timeout) {
        // Waiting for this frame's depth: the frames in flight go out meanwhile.
        gst_buffer_unref(colorBuffer);
        unrefPads();
        const GstFlowReturn pushed = pushReceived(self, true);
        return pushed != GST_FLOW_OK ? pushed : GST_AGGREGATOR_FLOW_NEED_DATA;
    }
    if (!s.depthFrame && gst_aggregator_pad_is_eos(depth)) {
        GST_ELEMENT_ERROR(self, STREAM, FAILED, ("The depth stream ended before its first frame"), (nullptr));
        gst_buffer_unref(colorBuffer);
        unrefPads();
        return GST_FLOW_ERROR;
    }
    gst_aggregator_pad_drop_buffer(color);

    // The output's timestamp: the colour's running time in the output segment.
    GstClockTime pts = GST_BUFFER_PTS(colorBuffer);
    if (GST_CLOCK_TIME_IS_VALID(colorTime)) {
        GST_OBJECT_LOCK(agg);
        pts = gst_segment_position_from_running_time(&GST_AGGREGATOR_PAD(agg->srcpad)->segment, GST_FORMAT_TIME,
                                                     colorTime);
        GST_OBJECT_UNLOCK(agg);
    }
    if (GST_CLOCK_TIME_IS_VALID(duration))
        s.lastDuration = duration;

    GstFlowReturn ret = GST_FLOW_OK;
    GstBuffer* outbuf = nullptr; // the GL path's
    GST_OBJECT_LOCK(self);
    GstVideoInfo depthInfo = depthPad->info;
    GstVideoInfo colorInfo = colorPad->info;
    GST_OBJECT_UNLOCK(self);
    if (!s.depthFrame) {
        // Live: no depth yet by this colour frame's deadline; it is dropped, not waited for.
        GST_DEBUG_OBJECT(self, "no depth by %" GST_TIME_FORMAT ": colour frame dropped", GST_TIME_ARGS(colorTime));
    } else if (s.glOutput) {
        // GL memory, one frame at a time on the pipeline's context; any frames still in flight
        // from system memory (caps renegotiated) go out first.
        ret = pushReceived(self, true);
        if (ret == GST_FLOW_OK &&
            (ret = GST_VIDEO_AGGREGATOR_CLASS(gst_defocus_parent_class)->create_output_buffer(vagg, &outbuf)) ==
                GST_FLOW_OK &&
            outbuf) {
            GST_BUFFER_PTS(outbuf) = pts;
            GST_BUFFER_DTS(outbuf) = GST_CLOCK_TIME_NONE;
            GST_BUFFER_DURATION(outbuf) = duration;
            ret = renderGl(self, outbuf, colorBuffer, &colorInfo, s.depthFrame, &depthInfo);
        }
    } else {
        // The colour in the output's format (the colour pad converts it), or I420, NV12 and YUY2
        // as they came (the filter converts them, on the GPU where it has one), the depth as it
        // came, submitted; the oldest frame in flight comes out when the filter holds its
        // kFramesInFlight, and every one when no colour frame waits behind this one (a frame is
        // never held for input that is not there: no latency added).
        auto* colorClass = GST_VIDEO_AGGREGATOR_PAD_GET_CLASS(colorPad);
        GstVideoFrame prepared{};
        const bool asItCame = yuvLayout(colorInfo).has_value();
        const bool mapped = asItCame ? gst_video_frame_map(&prepared, &colorInfo, colorBuffer, GST_MAP_READ)
                                     : colorClass->prepare_frame(colorPad, vagg, colorBuffer, &prepared);
        if (!mapped || !prepared.buffer) {
            GST_ELEMENT_ERROR(self, STREAM, FAILED, ("A colour or depth frame could not be mapped"), (nullptr));
            ret = GST_FLOW_ERROR;
        } else {
            ret = submit(self, &prepared, s.depthFrame, &depthInfo, pts, duration);
        }
        if (asItCame && prepared.buffer)
            gst_video_frame_unmap(&prepared);
        else if (!asItCame)
            colorClass->clean_frame(colorPad, vagg, &prepared);
        if (ret == GST_FLOW_OK)
            ret = pushReceived(self, !gst_aggregator_pad_has_buffer(color));
    }
    gst_buffer_unref(colorBuffer);
    unrefPads();
    // The base class' next deadline (live) is the end of this frame.
    GST_OBJECT_LOCK(agg);
    GstSegment& segment = GST_AGGREGATOR_PAD(agg->srcpad)->segment;
    if (GST_CLOCK_TIME_IS_VALID(pts))
        segment.position = GST_CLOCK_TIME_IS_VALID(duration) ? pts + duration : pts;
    GST_OBJECT_UNLOCK(agg);
    if (ret != GST_FLOW_OK || !outbuf) {
        if (outbuf)
            gst_buffer_unref(outbuf);
        return ret;
    }
    return gst_aggregator_finish_buffer(agg, outbuf);
}

GstFlowReturn flush(GstAggregator* agg)
{
    stateOf(agg).resetPending = true;
    stateOf(agg).depthStale = true;
    return GST_AGGREGATOR_CLASS(gst_defocus_parent_class)->flush(agg);
}

gboolean stop(GstAggregator* agg)
{
    State& s = stateOf(agg);
    // The streaming task has stopped and released the context: it can be made current here.
    dropInFlight(s);
    s.filter.reset();
    dropGl(s);
    s.warned.clear();
    s.resetPending = false;
    s.depthStale = false;
    gst_clear_buffer(&s.depthFrame);
    {
        std::lock_guard guard(s.lock);
        s.applied = 0;
    }
    return GST_AGGREGATOR_CLASS(gst_defocus_parent_class)->stop(agg);
}

void finalize(GObject* object)
{
    State& s = *GST_DEFOCUS(object)->state;
    for (InFlight& frame : s.inFlight)
        unmap(frame);
    gst_clear_buffer(&s.depthFrame);
    dropGl(s);
    gst_clear_object(&s.otherContext);
    gst_clear_object(&s.display);
    delete &s;
    G_OBJECT_CLASS(gst_defocus_parent_class)->finalize(object);
}

void installDouble(GObjectClass* klass, guint id, const char* name, const char* blurb, double low, double high,
                   double value, GParamFlags flags = kFlags)
{
    g_object_class_install_property(klass, id, g_param_spec_double(name, name, blurb, low, high, value, flags));
}

} // namespace

static void gst_defocus_class_init(GstDefocusClass* klass)
{
    GST_DEBUG_CATEGORY_INIT(gst_defocus_debug, "defocus", 0, "defocus depth-of-field filter");
    auto* gobject = G_OBJECT_CLASS(klass);
    auto* element = GST_ELEMENT_CLASS(klass);
    auto* agg = GST_AGGREGATOR_CLASS(klass);
    auto* vagg = GST_VIDEO_AGGREGATOR_CLASS(klass);

    gobject->set_property = setProperty;
    gobject->get_property = getProperty;
    gobject->finalize = finalize;

    // Ranges are the command line's, from the library's one definition of them (defocus::limits);
    // defaults are the library's (defocus::Settings), as the command line's are.
    namespace limits = defocus::limits;
    const defocus::Settings defaults;
    installDouble(gobject, PROP_FOCUS, "focus",
                  "Distance in focus, metres ('inf' for infinity); setting it turns autofocus off", limits::kFocusM[0],
                  limits::kFocusM[1], defaults.lens.focusM, kControllable);
    g_object_class_install_property(
        gobject, PROP_AUTOFOCUS,
        g_param_spec_boolean("autofocus", "autofocus",
                             "Follow the depth of the centre of the frame, frame by frame (the command line's "
                             "--focus track: a critically damped spring in dioptres); off: the focus property",
                             TRUE, kFlags));
    installDouble(gobject, PROP_AUTOFOCUS_TIME_CONSTANT, "autofocus-time-constant",
                  "Autofocus time constant, seconds (a step is 95 % done after 4.7 of them; 0 jumps)",
                  limits::kTimeConstantS[0], limits::kTimeConstantS[1], defaults.autofocus.timeConstantS);
    installDouble(gobject, PROP_F_NUMBER, "f-number", "Aperture as an f-number N (smaller = more blur)",
                  limits::kFNumber[0], limits::kFNumber[1], defaults.lens.fNumber, kControllable);
    installDouble(gobject, PROP_FOCAL_LENGTH, "focal-length", "Lens focal length, millimetres",
                  limits::kFocalLengthMm[0], limits::kFocalLengthMm[1], defaults.lens.focalLengthMm, kControllable);
    installDouble(gobject, PROP_SENSOR_WIDTH, "sensor-width", "Sensor width the image spans, millimetres",
                  limits::kSensorWidthMm[0], limits::kSensorWidthMm[1], defaults.lens.sensorWidthMm, kControllable);
    g_object_class_install_property(
        gobject, PROP_FOV_FROM,
        g_param_spec_enum("fov-from", "fov-from", "Where the sensor width spans the image", fovFromType(), 0, kFlags));
    installDouble(gobject, PROP_MAX_COC, "max-coc", "Largest blur diameter, pixels", limits::kMaxCocPx[0],
                  limits::kMaxCocPx[1], defaults.lens.maxCocPx, kControllable);
    g_object_class_install_property(
        gobject, PROP_COC_MODEL,
        g_param_spec_enum("coc-model", "coc-model", "How depth becomes blur", cocModelType(), 0, kFlags));
    installDouble(gobject, PROP_NEAR, "near", "focal-range model: metres where near blur reaches max-coc",
                  limits::kNearFarM[0], limits::kNearFarM[1], defaults.lens.nearM, kControllable);
    installDouble(gobject, PROP_FAR, "far", "focal-range model: metres where far blur reaches max-coc",
                  limits::kNearFarM[0], limits::kNearFarM[1], defaults.lens.farM, kControllable);
    g_object_class_install_property(
        gobject, PROP_QUALITY,
        g_param_spec_enum("quality", "quality",
                          "Preset from the accuracy benchmark; samples, hexagon, precision, resolution and near-field "
                          "override it",
                          qualityType(), 1, kFlags));
    g_object_class_install_property(
        gobject, PROP_SAMPLES,
        g_param_spec_int("samples", "samples", "Taps per directional blur, 2..64; 0 = the quality preset's", 0,
                         limits::kSamples[1], 0, kFlags));
    g_object_class_install_property(
        gobject, PROP_HEXAGON,
        g_param_spec_enum("hexagon", "hexagon", "How the blurs make the hexagon", hexagonType(), 0, kFlags));
    g_object_class_install_property(
        gobject, PROP_PRECISION,
        g_param_spec_enum("precision", "precision", "Intermediate render targets", precisionType(), 0, kFlags));
    g_object_class_install_property(
        gobject, PROP_RESOLUTION,
        g_param_spec_enum("resolution", "resolution", "Size the blurs run at", resolutionType(), 0, kFlags));
    g_object_class_install_property(
        gobject, PROP_NEAR_FIELD,
        g_param_spec_boolean("near-field", "near-field",
                             "Spread blurred foreground over what is behind it (every preset: on; setting it "
                             "overrides the preset)",
                             TRUE, kFlags));
    g_object_class_install_property(
        gobject, PROP_HIGHLIGHT_SPRITES,
        g_param_spec_boolean("highlight-sprites", "highlight-sprites",
                             "Rhombi: lights brighter than white scatter in the aperture's shape with exact edges", TRUE, kFlags));
    installDouble(gobject, PROP_HIGHLIGHT_GAIN, "highlight-gain",
                  "Scale near-clipped pixels that get blurred up to this, so lights bloom (1 = off)",
                  limits::kHighlightGain[0], limits::kHighlightGain[1], defaults.quality.highlightGain);
    g_object_class_install_property(
        gobject, PROP_BLADES,
        g_param_spec_int("blades", "blades",
                         "Aperture blades: 0 = circular, else the polygon's corners, 3..16 (1 and 2 become 3)", 0,
                         limits::kBlades[1], defaults.lens.blades, kControllable));
    installDouble(gobject, PROP_BLADE_ROTATION, "blade-rotation",
                  "Aperture rotation, degrees counter-clockwise, as Blender Cycles: at 0 an edge faces right "
                  "(the hexagon's corner on top; 30 = flat top)",
                  limits::kBladeRotationDeg[0], limits::kBladeRotationDeg[1], defaults.lens.bladeRotationDeg,
                  kControllable);
    installDouble(gobject, PROP_APERTURE_RATIO, "aperture-ratio",
                  "Anamorphic squeeze: the aperture's width is divided by it (2 = tall ovals)",
                  limits::kApertureRatio[0], limits::kApertureRatio[1], defaults.lens.apertureRatio, kControllable);
    installDouble(gobject, PROP_DEPTH_SCALE, "depth-scale", "Units per metre of the 16-bit depth (TUM RGB-D: 5000)",
                  limits::kDepthScale[0], limits::kDepthScale[1], defaults.depthScale);
    g_object_class_install_property(
        gobject, PROP_VIEW,
        g_param_spec_enum("view", "view", "What to output", viewType(), 4, kFlags));
    g_object_class_install_property(
        gobject, PROP_POST_TIMINGS,
        g_param_spec_boolean("post-timings", "post-timings",
                             "Post each frame's timings and plan as a 'defocus-timings' element message", FALSE,
                             kFlags));

    gst_element_class_set_static_metadata(
        element, "Depth of field", "Filter/Effect/Video",
        "Gives colour + depth video the depth of field of a real lens, with the bokeh of a real aperture (OpenGL 4.5, headless EGL)",
        "defocus developers");
    gst_element_class_add_static_pad_template(element, &srcTemplate);
    gst_element_class_add_static_pad_template_with_gtype(element, &colorTemplate, GST_TYPE_VIDEO_AGGREGATOR_CONVERT_PAD);
    gst_element_class_add_static_pad_template_with_gtype(element, &depthTemplate, GST_TYPE_VIDEO_AGGREGATOR_PAD);
    element->release_pad = releasePad;
    element->set_context = setContext;

    agg->create_new_pad = createNewPad;
    agg->sink_query = sinkQuery;
    agg->src_query = srcQuery;
    agg->propose_allocation = proposeAllocation;
    agg->decide_allocation = decideAllocation;
    agg->sink_event = sinkEvent;
    agg->negotiated_src_caps = negotiatedSrcCaps;
    agg->update_src_caps = updateSrcCaps;
    agg->fixate_src_caps = fixateSrcCaps;
    agg->flush = flush;
    agg->stop = stop;
    agg->aggregate = aggregate;
    vagg->find_best_format = nullptr;
}

static void gst_defocus_init(GstDefocus* self)
{
    self->state = new State;
    // Autofocus by default, as the command line's focus is automatic by default; in a stream
    // (often live, of a scene that changes) it follows the focus frame by frame, as `--focus
    // track` does, rather than fixing it at the first frame as `--focus auto` does.
    self->state->settings.autofocus.mode = defocus::AutofocusOptions::Mode::Follow;
}

static gboolean plugin_init(GstPlugin* plugin)
{
    defocus::gst::takeLibraryLog();
    return gst_element_register(plugin, "defocus", GST_RANK_NONE, GST_TYPE_DEFOCUS) &&
           gst_element_register(plugin, "defocussrc", GST_RANK_NONE, GST_TYPE_DEFOCUS_SRC);
}

#define PACKAGE "defocus"
GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, defocus,
                  "Depth of field with polygonal or round bokeh for colour + depth video", plugin_init, DEFOCUS_VERSION,
                  "LGPL", "defocus", "the defocus source tree (no public URL)")
