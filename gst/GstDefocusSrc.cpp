// SPDX-License-Identifier: LGPL-2.1-or-later
// The GStreamer element `defocussrc`: what `defocus INPUT --depth DEPTH` reads (TUM folders named
// by timestamp, folder pairs, a colour camera with a Z16 depth camera, ...) as two src pads, `color`
// (BGR) and `depth` (GRAY16_LE in depth-scale units per metre), one buffer on each per frame with
// the same timestamp and duration: recorded capture times at a variable rate (framerate=0/1, each
// buffer lasting until the next), frame / rate at a constant one. Through libdefocus' public
// defocus::Source; one streaming thread pushes both.
//   gst-launch-1.0 defocussrc location=data/tum_fr1_rpy depth-scale=5000 name=s
//     defocus name=d focus=1.2 f-number=1.4 depth-scale=5000 ! videoconvert ! autovideosink
//     s.color ! queue ! d.color  s.depth ! queue ! d.depth                 (one line)
#include "gst/GstDefocusSrc.hpp"
#include "gst/LibraryLog.hpp"

#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include <defocus/defocus.hpp>
#include <gst/base/gstflowcombiner.h>
#include <gst/video/video.h>
#include <opencv2/core.hpp>

GST_DEBUG_CATEGORY_STATIC(gst_defocus_src_debug);
#define GST_CAT_DEFAULT gst_defocus_src_debug

namespace {

struct SrcState {
    std::mutex lock; ///< guards the properties
    std::string location;
    std::string depthLocation;
    double inputDepthScale = 0.0; ///< 0 = the input's own (5000 TUM, 1000 otherwise)
    double depthScale = 1000.0;
    int width = 640;
    int height = 480;
    double fps = 30.0;
    gint64 numBuffers = -1;
    int readThreads = -1; ///< -1: defocus::defaultReadThreads()

    // Opened in READY->PAUSED, used by the streaming thread, closed in PAUSED->READY.
    std::unique_ptr<defocus::Source> source;
    bool live = false;
    std::optional<defocus::SourceFrame> first; ///< read at start, to fix the caps
    /// Variable rate (the input's own timestamps): the frame after the one being pushed, read
    /// ahead for its timestamp, which ends the pushed one; and an error met reading it.
    bool variable = false;
    std::optional<defocus::SourceFrame> ahead;
    std::optional<std::string> aheadError;
    bool aheadEnded = false; ///< reading ahead found the end
    GstClockTime lastDuration = GST_CLOCK_TIME_NONE;
    bool started = false;                      ///< stream-start, caps and segment sent
    gint64 pushed = 0;
    double firstTimestampS = 0.0;
    GstVideoInfo colorInfo{};
    GstVideoInfo depthInfo{};
    GstFlowCombiner* combiner = nullptr;
};

} // namespace

struct _GstDefocusSrc {
    GstElement parent;
    GstPad* color;
    GstPad* depth;
    SrcState* state;
};

G_DEFINE_TYPE(GstDefocusSrc, gst_defocus_src, GST_TYPE_ELEMENT)

namespace {

enum Property {
    PROP_0,
    PROP_LOCATION,
    PROP_DEPTH_LOCATION,
    PROP_INPUT_DEPTH_SCALE,
    PROP_DEPTH_SCALE,
    PROP_WIDTH,
    PROP_HEIGHT,
    PROP_FPS,
    PROP_NUM_BUFFERS,
    PROP_READ_THREADS,
};

GstStaticPadTemplate colorTemplate = GST_STATIC_PAD_TEMPLATE(
    "color", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(GST_VIDEO_CAPS_MAKE("BGR")));
GstStaticPadTemplate depthTemplate = GST_STATIC_PAD_TEMPLATE(
    "depth", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(GST_VIDEO_CAPS_MAKE("GRAY16_LE")));

constexpr auto kFlags = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_READY);

SrcState& stateOf(GstDefocusSrc* self)
{
    return *self->state;
}

/// Frame rate as a fraction; 0/1 where the input does not say.
void rateFraction(double fps, gint& num, gint& den)
{
    if (fps > 0.0)
        gst_util_double_to_fraction(fps, &num, &den);
    else
        num = 0, den = 1;
}

/// Sends stream-start, caps and a TIME segment on one pad.
bool startPad(GstDefocusSrc* self, GstPad* pad, const char* id, const GstVideoInfo& info, guint group)
{
    gchar* streamId = gst_pad_create_stream_id(pad, GST_ELEMENT(self), id);
    GstEvent* start = gst_event_new_stream_start(streamId);
    g_free(streamId);
    gst_event_set_group_id(start, group);
    gst_pad_push_event(pad, start);
    GstCaps* caps = gst_video_info_to_caps(&info);
    const bool ok = gst_pad_push_event(pad, gst_event_new_caps(caps));
    gst_caps_unref(caps);
    GstSegment segment;
    gst_segment_init(&segment, GST_FORMAT_TIME);
    gst_pad_push_event(pad, gst_event_new_segment(&segment));
    return ok;
}

/// The colour as a BGR buffer (rows copied to GStreamer's stride).
GstBuffer* colorBuffer(const cv::Mat& bgr, const GstVideoInfo& info)
{
    GstBuffer* buffer = gst_buffer_new_allocate(nullptr, GST_VIDEO_INFO_SIZE(&info), nullptr);
    GstVideoFrame frame;
    gst_video_frame_map(&frame, &info, buffer, GST_MAP_WRITE);
    const int stride = GST_VIDEO_FRAME_PLANE_STRIDE(&frame, 0);
    auto* data = static_cast<guint8*>(GST_VIDEO_FRAME_PLANE_DATA(&frame, 0));
    cv::Mat out(bgr.rows, bgr.cols, CV_8UC3, data, static_cast<std::size_t>(stride));
    bgr.copyTo(out);
    gst_video_frame_unmap(&frame);
    return buffer;
}

/// The frame's depth as GRAY16_LE in `scale` units per metre: 16-bit depth read at that scale as
/// it is; otherwise from metres, rounded, where no measurement (0, NaN, negative) and beyond
/// 65535 units stay 0 and 65535. No depth at all: zeros, which the filter reads as "no
/// measurement", so the frame passes in focus as the command line passes it.
GstBuffer* depthBuffer(const defocus::Frame& source, const GstVideoInfo& info, double scale)
{
    GstBuffer* buffer = gst_buffer_new_allocate(nullptr, GST_VIDEO_INFO_SIZE(&info), nullptr);
    GstVideoFrame frame;
    gst_video_frame_map(&frame, &info, buffer, GST_MAP_WRITE);
    const int stride = GST_VIDEO_FRAME_PLANE_STRIDE(&frame, 0);
    auto* data = static_cast<guint8*>(GST_VIDEO_FRAME_PLANE_DATA(&frame, 0));
    if (source.depth.type() == CV_16UC1 && source.depthScale == scale && G_BYTE_ORDER == G_LITTLE_ENDIAN) {
        source.depth.copyTo(cv::Mat(source.depth.size(), CV_16UC1, data, static_cast<std::size_t>(stride)));
        gst_video_frame_unmap(&frame);
        return buffer;
    }
    const cv::Mat metres = defocus::depthMetres(source);
    for (int y = 0; y < GST_VIDEO_INFO_HEIGHT(&info); ++y) {
        auto* row = reinterpret_cast<guint16*>(data + static_cast<std::ptrdiff_t>(y) * stride);
        for (int x = 0; x < GST_VIDEO_INFO_WIDTH(&info); ++x) {
            const float m = metres.empty() ? 0.0f : metres.at<float>(y, x);
            const double units = (m > 0.0f && std::isfinite(m)) ? std::round(m * scale) : 0.0;
            row[x] = GUINT16_TO_LE(static_cast<guint16>(std::min(units, 65535.0)));
        }
    }
    gst_video_frame_unmap(&frame);
    return buffer;
}

void pushEos(GstDefocusSrc* self)
{
    gst_pad_push_event(self->color, gst_event_new_eos());
    gst_pad_push_event(self->depth, gst_event_new_eos());
}

/// The streaming thread: one frame per call, pushed on both pads.
void loop(gpointer data)
{
    auto* self = GST_DEFOCUS_SRC(data);
    SrcState& st = stateOf(self);
    const defocus::gst::LibraryCall call(GST_ELEMENT(self));
    std::optional<defocus::SourceFrame> frame;
    double scale = 1000.0;
    gint64 limit = -1;
    {
        std::lock_guard lock(st.lock);
        scale = st.depthScale;
        limit = st.numBuffers;
    }
    try {
        if (limit >= 0 && st.pushed >= limit)
            frame.reset();
        else if (st.first)
            frame = std::exchange(st.first, std::nullopt);
        else if (st.ahead)
            frame = std::exchange(st.ahead, std::nullopt);
        else if (st.aheadError)
            throw defocus::SourceReadError(*st.aheadError);
        else if (st.aheadEnded)
            frame.reset();
        else
            frame = st.source->next();
    } catch (const defocus::Error& error) {
        GST_ELEMENT_ERROR(self, RESOURCE, READ, ("%s", error.what()), ("after %" G_GINT64_FORMAT " frames", st.pushed));
        pushEos(self);
        gst_pad_pause_task(self->color);
        return;
    }
    if (!frame) {
        GST_INFO_OBJECT(self, "end of input after %" G_GINT64_FORMAT " frames", st.pushed);
        pushEos(self);
        gst_pad_pause_task(self->color);
        return;
    }
    if (frame->color.type() != CV_8UC3) {
        GST_ELEMENT_ERROR(self, STREAM, FORMAT, ("%s is linear float colour, which GStreamer 1.22's raw video "
                                                 "cannot carry: use the defocus command line for it", frame->name.c_str()),
                          (nullptr));
        pushEos(self);
        gst_pad_pause_task(self->color);
        return;
    }

    if (!st.started) {
        // Recorded capture times (TUM lists, files named by timestamp) are never evenly spaced:
        // variable rate, each buffer lasting until the next one's time. Otherwise the input's rate.
        st.variable = !st.live && frame->timestampS > 0.0;
        gint num = 0, den = 1;
        if (!st.variable)
            rateFraction(st.source->frameRate(), num, den);
        gst_video_info_set_format(&st.colorInfo, GST_VIDEO_FORMAT_BGR, static_cast<guint>(frame->color.cols),
                                  static_cast<guint>(frame->color.rows));
        const cv::Size depthSize = frame->depth.empty() ? frame->color.size() : frame->depth.size();
        gst_video_info_set_format(&st.depthInfo, GST_VIDEO_FORMAT_GRAY16_LE, static_cast<guint>(depthSize.width),
                                  static_cast<guint>(depthSize.height));
        GST_VIDEO_INFO_FPS_N(&st.colorInfo) = GST_VIDEO_INFO_FPS_N(&st.depthInfo) = num;
        GST_VIDEO_INFO_FPS_D(&st.colorInfo) = GST_VIDEO_INFO_FPS_D(&st.depthInfo) = den;
        const guint group = gst_util_group_id_next();
        if (!startPad(self, self->color, "color", st.colorInfo, group) ||
            !startPad(self, self->depth, "depth", st.depthInfo, group))
            GST_DEBUG_OBJECT(self, "a caps event was not taken (unlinked pad?)");
        st.firstTimestampS = frame->timestampS;
        st.started = true;
    }
    if (frame->color.cols != GST_VIDEO_INFO_WIDTH(&st.colorInfo) ||
        frame->color.rows != GST_VIDEO_INFO_HEIGHT(&st.colorInfo) ||
        (!frame->depth.empty() && (frame->depth.cols != GST_VIDEO_INFO_WIDTH(&st.depthInfo) ||
                                   frame->depth.rows != GST_VIDEO_INFO_HEIGHT(&st.depthInfo)))) {
        GST_ELEMENT_ERROR(self, STREAM, FORMAT,
                          ("%s: frame %" G_GSIZE_FORMAT " changes size (%dx%d colour, %dx%d depth, after %dx%d and %dx%d)",
                           frame->name.c_str(), frame->index, frame->color.cols, frame->color.rows,
                           frame->depth.cols, frame->depth.rows, GST_VIDEO_INFO_WIDTH(&st.colorInfo),
                           GST_VIDEO_INFO_HEIGHT(&st.colorInfo), GST_VIDEO_INFO_WIDTH(&st.depthInfo),
                           GST_VIDEO_INFO_HEIGHT(&st.depthInfo)),
                          (nullptr));
        pushEos(self);
        gst_pad_pause_task(self->color);
        return;
    }

    // Timestamps: a camera's frames at the pipeline's running time when they arrive; recorded
    // frames at their capture time from the first (TUM, file names), else at frame / rate.
    GstClockTime pts = GST_CLOCK_TIME_NONE, duration = GST_CLOCK_TIME_NONE;
    const gint num = GST_VIDEO_INFO_FPS_N(&st.colorInfo), den = GST_VIDEO_INFO_FPS_D(&st.colorInfo);
    if (num > 0)
        duration = gst_util_uint64_scale_int(GST_SECOND, den, num);
    if (st.live) {
        if (GstClock* clock = gst_element_get_clock(GST_ELEMENT(self))) {
            const GstClockTime now = gst_clock_get_time(clock);
            const GstClockTime base = gst_element_get_base_time(GST_ELEMENT(self));
            pts = now > base ? now - base : 0;
            gst_object_unref(clock);
        }
    } else if (st.variable) {
        const auto ptsOf = [&st](const defocus::SourceFrame& f) {
            return static_cast<GstClockTime>(std::llround(std::max(0.0, f.timestampS - st.firstTimestampS) * GST_SECOND));
        };
        pts = ptsOf(*frame);
        if (!st.ahead && !st.aheadError && !st.aheadEnded && (limit < 0 || st.pushed + 1 < limit)) {
            try {
                st.ahead = st.source->next();
                st.aheadEnded = !st.ahead;
            } catch (const defocus::Error& error) {
                st.aheadError = error.what(); // reported after this frame
            }
        }
        if (st.ahead && ptsOf(*st.ahead) > pts)
            duration = ptsOf(*st.ahead) - pts;
        else if (GST_CLOCK_TIME_IS_VALID(st.lastDuration))
            duration = st.lastDuration; // the last frame: as long as the one before
        else if (st.source->frameRate() > 0.0)
            duration = static_cast<GstClockTime>(std::llround(GST_SECOND / st.source->frameRate()));
        st.lastDuration = duration;
    } else {
        pts = GST_CLOCK_TIME_IS_VALID(duration) ? static_cast<GstClockTime>(st.pushed) * duration
                                                : static_cast<GstClockTime>(st.pushed) * (GST_SECOND / 30);
    }

    GstBuffer* color = colorBuffer(frame->color, st.colorInfo);
    GstBuffer* depth = depthBuffer(*frame, st.depthInfo, scale);
    for (GstBuffer* b : {color, depth}) {
        GST_BUFFER_PTS(b) = pts;
        GST_BUFFER_DURATION(b) = duration;
        GST_BUFFER_OFFSET(b) = static_cast<guint64>(st.pushed);
    }
    ++st.pushed;
    // Colour first, then depth; the combined result stops the task only when neither pad can go on.
    GstFlowReturn ret = gst_flow_combiner_update_pad_flow(st.combiner, self->color, gst_pad_push(self->color, color));
    ret = gst_flow_combiner_update_pad_flow(st.combiner, self->depth, gst_pad_push(self->depth, depth));
    if (ret != GST_FLOW_OK) {
        GST_INFO_OBJECT(self, "pausing: %s", gst_flow_get_name(ret));
        if (ret == GST_FLOW_EOS) {
            pushEos(self);
        } else if (ret == GST_FLOW_NOT_LINKED || ret < GST_FLOW_EOS) {
            GST_ELEMENT_FLOW_ERROR(self, ret);
            pushEos(self);
        }
        gst_pad_pause_task(self->color);
    }
}

bool openSource(GstDefocusSrc* self)
{
    SrcState& st = stateOf(self);
    defocus::SourceSettings settings;
    {
        std::lock_guard lock(st.lock);
        settings.input = st.location;
        settings.depth = st.depthLocation;
        if (st.inputDepthScale > 0.0)
            settings.depthScale = st.inputDepthScale;
        settings.depthUnits = true; // pushed as read where the scales agree
        settings.width = st.width;
        settings.height = st.height;
        settings.fps = st.fps;
        settings.readThreads = st.readThreads < 0 ? defocus::defaultReadThreads() : static_cast<std::size_t>(st.readThreads);
    }
    const defocus::gst::LibraryCall call(GST_ELEMENT(self));
    if (settings.input.empty()) {
        GST_ELEMENT_ERROR(self, RESOURCE, NOT_FOUND, ("defocussrc: no location given (a TUM folder, image folder, "
                                                      "image, video file or /dev/videoN)"), (nullptr));
        return false;
    }
    try {
        st.source = std::make_unique<defocus::Source>(settings);
        st.live = st.source->isLive();
        if (!st.live)
            GST_INFO_OBJECT(self, "a recorded clip is decoded on %zu thread(s) ahead of the streaming thread",
                            settings.readThreads);
        // The first frame fixes the caps; reading it here makes a bad input fail the state change.
        if (!st.live) {
            st.first = st.source->next();
            if (!st.first) {
                GST_ELEMENT_ERROR(self, RESOURCE, READ, ("%s gave no frames", settings.input.c_str()), (nullptr));
                return false;
            }
        }
    } catch (const defocus::Error& error) {
        GST_ELEMENT_ERROR(self, RESOURCE, OPEN_READ, ("%s", error.what()), (nullptr));
        st.source.reset();
        return false;
    }
    GST_INFO_OBJECT(self, "%s", st.source->describe().c_str());
    st.started = false;
    st.pushed = 0;
    gst_flow_combiner_reset(st.combiner);
    return true;
}

GstStateChangeReturn changeState(GstElement* element, GstStateChange transition)
{
    auto* self = GST_DEFOCUS_SRC(element);
    SrcState& st = stateOf(self);
    switch (transition) {
    case GST_STATE_CHANGE_READY_TO_PAUSED:
        if (!openSource(self))
            return GST_STATE_CHANGE_FAILURE;
        break;
    default:
        break;
    }
    GstStateChangeReturn ret = GST_ELEMENT_CLASS(gst_defocus_src_parent_class)->change_state(element, transition);
    if (ret == GST_STATE_CHANGE_FAILURE)
        return ret;
    switch (transition) {
    case GST_STATE_CHANGE_READY_TO_PAUSED:
        // Recorded input streams from PAUSED (it prerolls); a camera only in PLAYING.
        if (st.live)
            ret = GST_STATE_CHANGE_NO_PREROLL;
        else
            gst_pad_start_task(self->color, loop, self, nullptr);
        break;
    case GST_STATE_CHANGE_PAUSED_TO_PLAYING:
        if (st.live)
            gst_pad_start_task(self->color, loop, self, nullptr);
        break;
    case GST_STATE_CHANGE_PLAYING_TO_PAUSED:
        if (st.live) {
            gst_pad_pause_task(self->color);
            ret = GST_STATE_CHANGE_NO_PREROLL;
        }
        break;
    case GST_STATE_CHANGE_PAUSED_TO_READY:
        gst_pad_stop_task(self->color);
        st.source.reset();
        st.first.reset();
        st.ahead.reset();
        st.aheadError.reset();
        st.aheadEnded = false;
        st.lastDuration = GST_CLOCK_TIME_NONE;
        st.started = false;
        break;
    default:
        break;
    }
    return ret;
}

gboolean srcQuery(GstPad* pad, GstObject* parent, GstQuery* query)
{
    auto* self = GST_DEFOCUS_SRC(parent);
    SrcState& st = stateOf(self);
    switch (GST_QUERY_TYPE(query)) {
    case GST_QUERY_LATENCY: {
        // A camera: a frame is out one frame period after its capture began at the latest.
        GstClockTime frame = 0;
        if (st.live && GST_VIDEO_INFO_FPS_N(&st.colorInfo) > 0)
            frame = gst_util_uint64_scale_int(GST_SECOND, GST_VIDEO_INFO_FPS_D(&st.colorInfo),
                                              GST_VIDEO_INFO_FPS_N(&st.colorInfo));
        else if (st.live)
            frame = GST_SECOND / 30;
        gst_query_set_latency(query, st.live, frame, frame);
        return TRUE;
    }
    case GST_QUERY_SCHEDULING:
        gst_query_set_scheduling(query, GST_SCHEDULING_FLAG_SEQUENTIAL, 1, -1, 0);
        gst_query_add_scheduling_mode(query, GST_PAD_MODE_PUSH);
        return TRUE;
    default:
        return gst_pad_query_default(pad, parent, query);
    }
}

gboolean srcEvent(GstPad* pad, GstObject* parent, GstEvent* event)
{
    switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_SEEK:
        GST_DEBUG_OBJECT(parent, "seeking is not supported");
        gst_event_unref(event);
        return FALSE;
    default:
        return gst_pad_event_default(pad, parent, event);
    }
}

void setProperty(GObject* object, guint id, const GValue* value, GParamSpec* spec)
{
    SrcState& st = stateOf(GST_DEFOCUS_SRC(object));
    std::lock_guard lock(st.lock);
    switch (id) {
    case PROP_LOCATION: st.location = g_value_get_string(value) ? g_value_get_string(value) : ""; break;
    case PROP_DEPTH_LOCATION: st.depthLocation = g_value_get_string(value) ? g_value_get_string(value) : ""; break;
    case PROP_INPUT_DEPTH_SCALE: st.inputDepthScale = g_value_get_double(value); break;
    case PROP_DEPTH_SCALE: st.depthScale = g_value_get_double(value); break;
    case PROP_WIDTH: st.width = g_value_get_int(value); break;
    case PROP_HEIGHT: st.height = g_value_get_int(value); break;
    case PROP_FPS: st.fps = g_value_get_double(value); break;
    case PROP_NUM_BUFFERS: st.numBuffers = g_value_get_int64(value); break;
    case PROP_READ_THREADS: st.readThreads = g_value_get_int(value); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, spec);
    }
}

void getProperty(GObject* object, guint id, GValue* value, GParamSpec* spec)
{
    SrcState& st = stateOf(GST_DEFOCUS_SRC(object));
    std::lock_guard lock(st.lock);
    switch (id) {
    case PROP_LOCATION: g_value_set_string(value, st.location.c_str()); break;
    case PROP_DEPTH_LOCATION: g_value_set_string(value, st.depthLocation.c_str()); break;
    case PROP_INPUT_DEPTH_SCALE: g_value_set_double(value, st.inputDepthScale); break;
    case PROP_DEPTH_SCALE: g_value_set_double(value, st.depthScale); break;
    case PROP_WIDTH: g_value_set_int(value, st.width); break;
    case PROP_HEIGHT: g_value_set_int(value, st.height); break;
    case PROP_FPS: g_value_set_double(value, st.fps); break;
    case PROP_NUM_BUFFERS: g_value_set_int64(value, st.numBuffers); break;
    case PROP_READ_THREADS: g_value_set_int(value, st.readThreads); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, spec);
    }
}

void finalize(GObject* object)
{
    auto* self = GST_DEFOCUS_SRC(object);
    gst_flow_combiner_free(self->state->combiner);
    delete self->state;
    G_OBJECT_CLASS(gst_defocus_src_parent_class)->finalize(object);
}

} // namespace

static void gst_defocus_src_class_init(GstDefocusSrcClass* klass)
{
    GST_DEBUG_CATEGORY_INIT(gst_defocus_src_debug, "defocussrc", 0, "defocus frame sources");
    auto* gobject = G_OBJECT_CLASS(klass);
    auto* element = GST_ELEMENT_CLASS(klass);
    gobject->set_property = setProperty;
    gobject->get_property = getProperty;
    gobject->finalize = finalize;
    element->change_state = changeState;

    g_object_class_install_property(
        gobject, PROP_LOCATION,
        g_param_spec_string("location", "location",
                            "What `defocus INPUT` reads: a TUM RGB-D folder, a folder of colour images, an image, a "
                            "video file or a camera (/dev/videoN)",
                            "", kFlags));
    g_object_class_install_property(
        gobject, PROP_DEPTH_LOCATION,
        g_param_spec_string("depth-location", "depth-location",
                            "defocus --depth: a depth folder (paired by sorted name), a depth image, a TUM depth list "
                            "or a Z16 depth camera (/dev/videoN); empty where the input names its own (TUM)",
                            "", kFlags));
    g_object_class_install_property(
        gobject, PROP_INPUT_DEPTH_SCALE,
        g_param_spec_double("input-depth-scale", "input-depth-scale",
                            "defocus --depth-scale: units per metre of the input's 16-bit depth images; 0 = 5000 "
                            "for TUM folders, 1000 otherwise",
                            0.0, defocus::limits::kDepthScale[1], 0.0, kFlags));
    g_object_class_install_property(
        gobject, PROP_DEPTH_SCALE,
        g_param_spec_double("depth-scale", "depth-scale",
                            "Units per metre of the depth pad's GRAY16_LE (give defocus the same depth-scale)",
                            defocus::limits::kDepthScale[0], defocus::limits::kDepthScale[1],
                            defocus::Settings().depthScale, kFlags));
    g_object_class_install_property(gobject, PROP_WIDTH,
                                    g_param_spec_int("width", "width", "Width asked of a camera, pixels", 1, G_MAXINT,
                                                     640, kFlags));
    g_object_class_install_property(gobject, PROP_HEIGHT,
                                    g_param_spec_int("height", "height", "Height asked of a camera, pixels", 1,
                                                     G_MAXINT, 480, kFlags));
    g_object_class_install_property(gobject, PROP_FPS,
                                    g_param_spec_double("fps", "fps", "Frame rate asked of a camera, Hz",
                                                        G_MINDOUBLE, G_MAXDOUBLE, 30.0, kFlags));
    g_object_class_install_property(
        gobject, PROP_NUM_BUFFERS,
        g_param_spec_int64("num-buffers", "num-buffers", "Frames to give before the end of stream (-1 = all)", -1,
                           G_MAXINT64, -1, kFlags));
    g_object_class_install_property(
        gobject, PROP_READ_THREADS,
        g_param_spec_int("read-threads", "read-threads",
                         "Threads decoding a recorded clip ahead of the streaming thread, several frames at once "
                         "(0 = on the streaming thread; -1 = the CPUs this process may use less one, at most 8)",
                         -1, 64, -1, kFlags));

    gst_element_class_add_static_pad_template(element, &colorTemplate);
    gst_element_class_add_static_pad_template(element, &depthTemplate);
    gst_element_class_set_static_metadata(
        element, "defocus frame source", "Source/Video",
        "Colour and depth frames as the defocus command line reads them: TUM RGB-D folders, folder pairs, "
        "images, video files, V4L2 colour and Z16 depth cameras",
        "defocus");
}

static void gst_defocus_src_init(GstDefocusSrc* self)
{
    self->state = new SrcState;
    GST_OBJECT_FLAG_SET(self, GST_ELEMENT_FLAG_SOURCE);
    self->state->combiner = gst_flow_combiner_new();
    self->color = gst_pad_new_from_static_template(&colorTemplate, "color");
    self->depth = gst_pad_new_from_static_template(&depthTemplate, "depth");
    for (GstPad* pad : {self->color, self->depth}) {
        gst_pad_set_query_function(pad, srcQuery);
        gst_pad_set_event_function(pad, srcEvent);
        gst_pad_use_fixed_caps(pad);
        gst_element_add_pad(GST_ELEMENT(self), pad);
        gst_flow_combiner_add_pad(self->state->combiner, pad);
    }
}
