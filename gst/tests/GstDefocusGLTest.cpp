// SPDX-License-Identifier: LGPL-2.1-or-later
// The `defocus` element through GstHarness: colour and depth pushed, the result pulled and held
// equal, byte for byte, to libdefocus on the same frame; passthrough, property changes,
// keyframed focus, EOS on either pad, flushing, caps it refuses, the errors it posts, one frame
// out per colour frame with its timestamp (a clip with gaps through defocussrc too), and GL memory
// in and out with no frame mapped for the CPU.
#include <atomic>
#include <cmath>
#include <filesystem>
#include <thread>
#include <unistd.h>
#include <cstring>
#include <utility>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <defocus/defocus.hpp>
#include <gst/app/gstappsink.h>
#include <gst/check/gstharness.h>
#include <gst/controller/gstinterpolationcontrolsource.h>
#include <gst/controller/gstdirectcontrolbinding.h>
#include <gst/gl/egl/gstgldisplay_egl.h>
#include <gst/gl/gl.h>
#include <gst/gst.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/ImageCompare.hpp"
#include "tests/YuvPlanes.hpp"

namespace {

constexpr GstClockTime kFrame = GST_SECOND / 30;

struct Rgbd {
    cv::Mat bgr;     ///< CV_8UC3
    cv::Mat depth16; ///< CV_16UC1, 5000 units per metre (TUM)
};

/// Line `line` (from 1) of the bundled clip's associations: colour and its depth.
Rgbd bundledFrame(int line)
{
    std::ifstream list(std::string(DEFOCUS_DATA_DIR) + "/tum_fr1_rpy/associations.txt");
    std::string text;
    for (int i = 0; i < line; ++i)
        std::getline(list, text);
    std::istringstream fields(text);
    std::string t1, rgb, t2, depth;
    fields >> t1 >> rgb >> t2 >> depth;
    const std::string dir = std::string(DEFOCUS_DATA_DIR) + "/tum_fr1_rpy/";
    return {cv::imread(dir + rgb, cv::IMREAD_COLOR), cv::imread(dir + depth, cv::IMREAD_UNCHANGED)};
}

GstBuffer* bufferOf(const cv::Mat& image, GstClockTime pts)
{
    const cv::Mat packed = image.isContinuous() ? image : image.clone();
    const gsize size = packed.total() * packed.elemSize();
    GstBuffer* buffer = gst_buffer_new_allocate(nullptr, size, nullptr);
    gst_buffer_fill(buffer, 0, packed.data, size);
    GST_BUFFER_PTS(buffer) = pts;
    GST_BUFFER_DURATION(buffer) = kFrame;
    return buffer;
}

/// Copies `buffer` (tightly packed `type` pixels of `size`) into a cv::Mat and unrefs it.
cv::Mat matOf(GstBuffer* buffer, cv::Size size, int type)
{
    cv::Mat out(size, type);
    EXPECT_EQ(gst_buffer_get_size(buffer), out.total() * out.elemSize());
    gst_buffer_extract(buffer, 0, out.data, out.total() * out.elemSize());
    gst_buffer_unref(buffer);
    return out;
}

std::string caps(const char* format, cv::Size size)
{
    return "video/x-raw,format=" + std::string(format) + ",width=" + std::to_string(size.width) +
           ",height=" + std::to_string(size.height) + ",framerate=30/1";
}

/// Success when `a` and `b` are the same image, byte for byte; else how they differ.
using defocus::test::identical;

/// The element with two harnesses: `color` also pulls from src.
struct Element {
    GstElement* element = nullptr;
    GstHarness* color = nullptr;
    GstHarness* depth = nullptr;
    GstBus* bus = gst_bus_new();

    /// `properties`: "name=value" pairs as gst-launch takes them.
    explicit Element(const std::vector<std::string>& properties, bool withDepth = true)
    {
        element = gst_element_factory_make("defocus", nullptr);
        if (!element)
            return;
        gst_element_set_bus(element, bus);
        for (const auto& property : properties) {
            const auto eq = property.find('=');
            gst_util_set_object_arg(G_OBJECT(element), property.substr(0, eq).c_str(),
                                    property.substr(eq + 1).c_str());
        }
        // Not live: the element waits for colour and depth of each frame, however long a frame
        // takes (a live pipeline drops a colour frame whose depth is late).
        color = gst_harness_new_with_element(element, "color", "src");
        gst_harness_set_live(color, FALSE);
        if (withDepth) {
            depth = gst_harness_new_with_element(element, "depth", nullptr);
            gst_harness_set_live(depth, FALSE);
        }
    }
    ~Element()
    {
        if (depth)
            gst_harness_teardown(depth);
        if (color)
            gst_harness_teardown(color);
        if (element)
            gst_object_unref(element);
        gst_object_unref(bus);
    }
    void setCaps(const char* colorFormat, cv::Size colorSize, const char* depthFormat, cv::Size depthSize,
                 const char* outFormat)
    {
        gst_harness_set_src_caps_str(color, caps(colorFormat, colorSize).c_str());
        if (depth)
            gst_harness_set_src_caps_str(depth, caps(depthFormat, depthSize).c_str());
        gst_harness_set_sink_caps_str(color, ("video/x-raw,format=" + std::string(outFormat)).c_str());
    }
    /// The first error posted within 10 s, or "".
    std::string error()
    {
        GstMessage* message = gst_bus_timed_pop_filtered(bus, 10 * GST_SECOND, GST_MESSAGE_ERROR);
        if (!message)
            return {};
        GError* err = nullptr;
        gchar* debug = nullptr;
        gst_message_parse_error(message, &err, &debug);
        std::string text = err->message;
        g_error_free(err);
        g_free(debug);
        gst_message_unref(message);
        return text;
    }
};

/// The library's result for the element's settings below.
cv::Mat library(const defocus::Settings& settings, const cv::Mat& color, const cv::Mat& depth)
{
    defocus::Filter filter(settings);
    return filter.process(color, depth);
}

defocus::Settings lensSettings()
{
    defocus::Settings s;
    s.lens.focusM = 1.0;
    s.lens.fNumber = 1.4;
    s.depthScale = 5000;
    return s;
}
const std::vector<std::string> kLens{"autofocus=false", "focus=1.0", "f-number=1.4", "depth-scale=5000"};

class GstDefocus : public ::testing::Test {
protected:
    void SetUp() override
    {
        GstElementFactory* factory = gst_element_factory_find("defocus");
        ASSERT_NE(factory, nullptr) << "the defocus plugin is not in " DEFOCUS_GST_PLUGIN_DIR;
        gst_object_unref(factory);
        frame_ = bundledFrame(9);
        ASSERT_FALSE(frame_.bgr.empty());
    }
    Rgbd frame_;
};

struct Variant {
    const char* name;
    const char* properties; ///< the element's, besides the lens
    defocus::Quality quality;
};

class GstDefocusMatchesLibrary : public GstDefocus, public ::testing::WithParamInterface<Variant> {};

// Defect caught: the element converting, pairing or setting up differently from the library
// (a property not passed on, a row stride ignored, colour channels swapped): any byte differs.
TEST_P(GstDefocusMatchesLibrary, TwoFramesByteForByte)
{
    std::vector<std::string> properties = kLens;
    std::istringstream extra(GetParam().properties);
    for (std::string p; extra >> p;)
        properties.push_back(p);
    Element e(properties);
    e.setCaps("BGR", frame_.bgr.size(), "GRAY16_LE", frame_.depth16.size(), "BGR");
    defocus::Settings settings = lensSettings();
    settings.quality = GetParam().quality;
    const Rgbd second = bundledFrame(3);
    for (int i = 0; i < 2; ++i) {
        const Rgbd& f = i == 0 ? frame_ : second;
        ASSERT_EQ(gst_harness_push(e.color, bufferOf(f.bgr, i * kFrame)), GST_FLOW_OK);
        ASSERT_EQ(gst_harness_push(e.depth, bufferOf(f.depth16, i * kFrame)), GST_FLOW_OK);
        const cv::Mat out = matOf(gst_harness_pull(e.color), f.bgr.size(), CV_8UC3);
        EXPECT_TRUE(identical(out, library(settings, f.bgr, f.depth16))) << "frame " << i;
        EXPECT_FALSE(identical(out, f.bgr)) << "frame " << i << " was not blurred";
    }
}

defocus::Quality quality(defocus::Quality::Preset preset, std::optional<defocus::Quality::Hexagon> hexagon = {})
{
    defocus::Quality q;
    q.preset = preset;
    q.hexagon = hexagon;
    return q;
}

INSTANTIATE_TEST_SUITE_P(
    PresetsAndKernels, GstDefocusMatchesLibrary,
    ::testing::Values(Variant{"balanced", "", quality(defocus::Quality::Preset::Balanced)},
                      Variant{"fast", "quality=fast", quality(defocus::Quality::Preset::Fast)},
                      Variant{"high", "quality=high", quality(defocus::Quality::Preset::High)},
                      Variant{"mcintosh", "hexagon=mcintosh",
                              quality(defocus::Quality::Preset::Balanced, defocus::Quality::Hexagon::McIntosh)}),
    [](const ::testing::TestParamInfo<Variant>& param) { return std::string(param.param.name); });

// Defect caught: the RGB-order or 4-byte paths (RGBx in and out) or big-endian depth (what
// pngdec gives) read wrongly: a swapped channel or byte order changes the result.
TEST_F(GstDefocus, RgbxColourAndBigEndianDepthMatchTheLibrary)
{
    Element e(kLens);
    e.setCaps("RGBx", frame_.bgr.size(), "GRAY16_BE", frame_.depth16.size(), "RGBx");
    cv::Mat rgbx, depthBe(frame_.depth16.size(), CV_16UC1);
    cv::cvtColor(frame_.bgr, rgbx, cv::COLOR_BGR2RGBA);
    for (int y = 0; y < depthBe.rows; ++y)
        for (int x = 0; x < depthBe.cols; ++x)
            depthBe.at<uint16_t>(y, x) = GUINT16_SWAP_LE_BE(frame_.depth16.at<uint16_t>(y, x));
    ASSERT_EQ(gst_harness_push(e.color, bufferOf(rgbx, 0)), GST_FLOW_OK);
    ASSERT_EQ(gst_harness_push(e.depth, bufferOf(depthBe, 0)), GST_FLOW_OK);
    const cv::Mat out = matOf(gst_harness_pull(e.color), frame_.bgr.size(), CV_8UC4);
    cv::Mat expected;
    cv::cvtColor(library(lensSettings(), frame_.bgr, frame_.depth16), expected, cv::COLOR_BGR2RGBA);
    EXPECT_TRUE(identical(out, expected));
}

// Defects caught: I420, NV12 or YUY2 converted by the colour pad on the CPU (GStreamer's converter
// rounds and resamples the chroma otherwise) instead of given to the filter as it came, the
// caps' matrix or range not passed on, an NV12 plane read as I420's, YUY2's pairs read as planes.
// The filter's result of its yuvToBgr() is the reference, byte for byte.
TEST_F(GstDefocus, I420Nv12AndYuy2GoToTheFilterAsTheyCame)
{
    struct Case {
        const char* format;
        const char* colorimetry;
        defocus::YuvImage::Matrix matrix;
        defocus::YuvImage::Range range;
    };
    using M = defocus::YuvImage::Matrix;
    using R = defocus::YuvImage::Range;
    using L = defocus::YuvImage::Layout;
    for (const Case& c : {Case{"I420", "bt709", M::Bt709, R::Limited}, Case{"NV12", "bt601", M::Bt601, R::Limited},
                          Case{"I420", "1:4:0:0", M::Bt601, R::Full}, Case{"YUY2", "bt601", M::Bt601, R::Limited}}) {
        const cv::Size size = frame_.bgr.size();
        const std::string format = c.format;
        defocus::YuvImage yuv = defocus::test::opencvYuv(
            frame_.bgr, format == "NV12" ? L::Nv12 : format == "YUY2" ? L::Yuyv : L::I420);
        yuv.matrix = c.matrix; // the caps' colorimetry: how the element reads the same bytes
        yuv.range = c.range;
        const cv::Mat packed = defocus::test::packedPlanes(yuv); // GStreamer's buffers at this width
        Element e(kLens);
        gst_harness_set_src_caps_str(e.color, (caps(c.format, size) + ",colorimetry=" + c.colorimetry).c_str());
        gst_harness_set_src_caps_str(e.depth, caps("GRAY16_LE", frame_.depth16.size()).c_str());
        gst_harness_set_sink_caps_str(e.color, "video/x-raw,format=BGR");
        ASSERT_EQ(gst_harness_push(e.color, bufferOf(packed, 0)), GST_FLOW_OK);
        ASSERT_EQ(gst_harness_push(e.depth, bufferOf(frame_.depth16, 0)), GST_FLOW_OK);
        const cv::Mat out = matOf(gst_harness_pull(e.color), size, CV_8UC3);
        EXPECT_TRUE(identical(out, library(lensSettings(), defocus::yuvToBgr(yuv), frame_.depth16)))
            << c.format << " " << c.colorimetry;
    }
}

// Defect caught: an all-in-focus frame changed on its way through (a colour conversion that
// rounds, an sRGB round trip, the alpha lost): with no blur the output is the input, exactly.
TEST_F(GstDefocus, InFocusPassesThroughBitExact)
{
    for (const char* format : {"BGRx", "BGR"}) {
        Element e({"autofocus=false", "max-coc=0"});
        e.setCaps(format, frame_.bgr.size(), "GRAY16_LE", frame_.depth16.size(), format);
        cv::Mat in = frame_.bgr;
        if (std::string(format) == "BGRx")
            cv::cvtColor(frame_.bgr, in, cv::COLOR_BGR2BGRA);
        ASSERT_EQ(gst_harness_push(e.color, bufferOf(in, 0)), GST_FLOW_OK);
        ASSERT_EQ(gst_harness_push(e.depth, bufferOf(frame_.depth16, 0)), GST_FLOW_OK);
        EXPECT_TRUE(identical(matOf(gst_harness_pull(e.color), in.size(), in.type()), in)) << format;
    }
}

// Defect caught: a property set while playing ignored (settings read once) or applied late.
TEST_F(GstDefocus, PropertyChangeTakesEffectOnTheNextFrame)
{
    Element e(kLens);
    e.setCaps("BGR", frame_.bgr.size(), "GRAY16_LE", frame_.depth16.size(), "BGR");
    ASSERT_EQ(gst_harness_push(e.color, bufferOf(frame_.bgr, 0)), GST_FLOW_OK);
    ASSERT_EQ(gst_harness_push(e.depth, bufferOf(frame_.depth16, 0)), GST_FLOW_OK);
    const cv::Mat first = matOf(gst_harness_pull(e.color), frame_.bgr.size(), CV_8UC3);
    g_object_set(e.element, "f-number", 8.0, nullptr);
    ASSERT_EQ(gst_harness_push(e.color, bufferOf(frame_.bgr, kFrame)), GST_FLOW_OK);
    ASSERT_EQ(gst_harness_push(e.depth, bufferOf(frame_.depth16, kFrame)), GST_FLOW_OK);
    const cv::Mat second = matOf(gst_harness_pull(e.color), frame_.bgr.size(), CV_8UC3);
    defocus::Settings f8 = lensSettings();
    f8.lens.fNumber = 8.0;
    EXPECT_TRUE(identical(first, library(lensSettings(), frame_.bgr, frame_.depth16)));
    EXPECT_TRUE(identical(second, library(f8, frame_.bgr, frame_.depth16)));
    EXPECT_FALSE(identical(first, second));
}

// Defect caught: keyframes not applied per frame (gst_object_sync_values missing, or called with
// running instead of stream time) or timings not posted: the focus of each frame's message and
// its image follow the linear ramp 1 m + 2 m/s * t.
TEST_F(GstDefocus, KeyframedFocusPullAndTimingMessages)
{
    Element e({"f-number=1.4", "depth-scale=5000", "post-timings=true"});
    GstControlSource* ramp = gst_interpolation_control_source_new();
    g_object_set(ramp, "mode", GST_INTERPOLATION_MODE_LINEAR, nullptr);
    // The direct binding maps [0, 1] onto the property's own range [0.001, inf]: set absolute.
    gst_object_add_control_binding(GST_OBJECT(e.element),
                                   gst_direct_control_binding_new_absolute(GST_OBJECT(e.element), "focus", ramp));
    gst_timed_value_control_source_set(GST_TIMED_VALUE_CONTROL_SOURCE(ramp), 0, 1.0);
    gst_timed_value_control_source_set(GST_TIMED_VALUE_CONTROL_SOURCE(ramp), GST_SECOND, 3.0);
    e.setCaps("BGR", frame_.bgr.size(), "GRAY16_LE", frame_.depth16.size(), "BGR");
    for (int i = 0; i < 3; ++i) {
        ASSERT_EQ(gst_harness_push(e.color, bufferOf(frame_.bgr, i * kFrame)), GST_FLOW_OK);
        ASSERT_EQ(gst_harness_push(e.depth, bufferOf(frame_.depth16, i * kFrame)), GST_FLOW_OK);
        const cv::Mat out = matOf(gst_harness_pull(e.color), frame_.bgr.size(), CV_8UC3);
        const double expected = 1.0 + 2.0 * static_cast<double>(i * kFrame) / GST_SECOND;
        GstMessage* message = gst_bus_timed_pop_filtered(e.bus, 5 * GST_SECOND, GST_MESSAGE_ELEMENT);
        ASSERT_NE(message, nullptr);
        const GstStructure* s = gst_message_get_structure(message);
        ASSERT_TRUE(gst_structure_has_name(s, "defocus-timings"));
        double focus = 0, total = 0;
        guint64 index = 99;
        ASSERT_TRUE(gst_structure_get_double(s, "focus", &focus));
        ASSERT_TRUE(gst_structure_get_double(s, "total-ms", &total));
        ASSERT_TRUE(gst_structure_get_uint64(s, "frame", &index));
        EXPECT_NEAR(focus, expected, 1e-9) << "frame " << i;
        EXPECT_GT(total, 0.0);
        EXPECT_EQ(index, static_cast<guint64>(i));
        EXPECT_NE(std::string(gst_structure_get_string(s, "plan")), "");
        gst_message_unref(message);
        defocus::Settings settings = lensSettings();
        settings.lens.focusM = focus;
        EXPECT_TRUE(identical(out, library(settings, frame_.bgr, frame_.depth16))) << "frame " << i;
    }
    gst_object_unref(ramp);
}

// Defect caught: the stream stalling or ending when its depth ends (one still depth image), or
// running on forever when its colour ends while depth goes on (imagefreeze).
TEST_F(GstDefocus, DepthEosKeepsTheLastDepthAndColourEosEndsTheStream)
{
    Element e(kLens);
    e.setCaps("BGR", frame_.bgr.size(), "GRAY16_LE", frame_.depth16.size(), "BGR");
    ASSERT_EQ(gst_harness_push(e.color, bufferOf(frame_.bgr, 0)), GST_FLOW_OK);
    ASSERT_EQ(gst_harness_push(e.depth, bufferOf(frame_.depth16, 0)), GST_FLOW_OK);
    gst_buffer_unref(gst_harness_pull(e.color));
    ASSERT_TRUE(gst_harness_push_event(e.depth, gst_event_new_eos()));
    const Rgbd other = bundledFrame(5);
    for (int i = 1; i < 3; ++i) {
        ASSERT_EQ(gst_harness_push(e.color, bufferOf(other.bgr, i * kFrame)), GST_FLOW_OK);
        const cv::Mat out = matOf(gst_harness_pull(e.color), frame_.bgr.size(), CV_8UC3);
        EXPECT_TRUE(identical(out, library(lensSettings(), other.bgr, frame_.depth16))) << "frame " << i;
    }
    ASSERT_TRUE(gst_harness_push_event(e.color, gst_event_new_eos()));
    bool eos = false;
    for (GstEvent* event; !eos && (event = gst_harness_pull_event(e.color));) {
        eos = GST_EVENT_TYPE(event) == GST_EVENT_EOS;
        gst_event_unref(event);
    }
    EXPECT_TRUE(eos);

    Element live(kLens);
    live.setCaps("BGR", frame_.bgr.size(), "GRAY16_LE", frame_.depth16.size(), "BGR");
    ASSERT_EQ(gst_harness_push(live.color, bufferOf(frame_.bgr, 0)), GST_FLOW_OK);
    ASSERT_EQ(gst_harness_push(live.depth, bufferOf(frame_.depth16, 0)), GST_FLOW_OK);
    gst_buffer_unref(gst_harness_pull(live.color));
    ASSERT_TRUE(gst_harness_push_event(live.color, gst_event_new_eos()));
    gst_harness_push(live.depth, bufferOf(frame_.depth16, kFrame));
    eos = false;
    for (GstEvent* event; !eos && (event = gst_harness_pull_event(live.color));) {
        eos = GST_EVENT_TYPE(event) == GST_EVENT_EOS;
        gst_event_unref(event);
    }
    EXPECT_TRUE(eos);
}

// Defect caught: a flushing seek leaving the element stalled or erroring: after flush-start /
// flush-stop on both pads and a new segment, frames flow again and still match the library.
TEST_F(GstDefocus, FlushThenStreamAgain)
{
    Element e(kLens);
    e.setCaps("BGR", frame_.bgr.size(), "GRAY16_LE", frame_.depth16.size(), "BGR");
    ASSERT_EQ(gst_harness_push(e.color, bufferOf(frame_.bgr, 0)), GST_FLOW_OK);
    ASSERT_EQ(gst_harness_push(e.depth, bufferOf(frame_.depth16, 0)), GST_FLOW_OK);
    gst_buffer_unref(gst_harness_pull(e.color));
    // One flush on both inputs, as a flushing seek makes upstream send it (one sequence number).
    const guint32 seqnum = gst_util_seqnum_next();
    for (GstHarness* h : {e.color, e.depth}) {
        GstEvent* start = gst_event_new_flush_start();
        GstEvent* stop = gst_event_new_flush_stop(TRUE);
        gst_event_set_seqnum(start, seqnum);
        gst_event_set_seqnum(stop, seqnum);
        ASSERT_TRUE(gst_harness_push_event(h, start));
        ASSERT_TRUE(gst_harness_push_event(h, stop));
        GstSegment segment;
        gst_segment_init(&segment, GST_FORMAT_TIME);
        ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_segment(&segment)));
    }
    const Rgbd other = bundledFrame(5);
    ASSERT_EQ(gst_harness_push(e.color, bufferOf(other.bgr, 0)), GST_FLOW_OK);
    ASSERT_EQ(gst_harness_push(e.depth, bufferOf(other.depth16, 0)), GST_FLOW_OK);
    GstBuffer* out = nullptr;
    // Buffers queued before the flush are gone; the first one after it is the new frame.
    while ((out = gst_harness_pull(e.color)) && GST_BUFFER_PTS(out) != 0)
        gst_buffer_unref(out);
    ASSERT_NE(out, nullptr);
    EXPECT_TRUE(identical(matOf(out, other.bgr.size(), CV_8UC3), library(lensSettings(), other.bgr, other.depth16)));
}

// Defect caught: a flushing seek that does not start a new stream in the filter (its reset
// skipped, or made for one path and not the other), so that the autofocus of the frames after the
// seek goes on from where the frames before it left it. With a slow autofocus (10 s) a frame whose
// centre lies twice as far as the frame before the flush is focused where a fresh filter focuses
// it, byte for byte, only if the seek reset the filter.
TEST_F(GstDefocus, FlushStartsANewStreamForTheAutofocus)
{
    Element e({"autofocus=true", "autofocus-time-constant=10", "f-number=1.4", "depth-scale=5000"});
    e.setCaps("BGR", frame_.bgr.size(), "GRAY16_LE", frame_.depth16.size(), "BGR");
    ASSERT_EQ(gst_harness_push(e.color, bufferOf(frame_.bgr, 0)), GST_FLOW_OK);
    ASSERT_EQ(gst_harness_push(e.depth, bufferOf(frame_.depth16, 0)), GST_FLOW_OK);
    gst_buffer_unref(gst_harness_pull(e.color));
    const guint32 seqnum = gst_util_seqnum_next();
    for (GstHarness* h : {e.color, e.depth}) {
        GstEvent* start = gst_event_new_flush_start();
        GstEvent* stop = gst_event_new_flush_stop(TRUE);
        gst_event_set_seqnum(start, seqnum);
        gst_event_set_seqnum(stop, seqnum);
        ASSERT_TRUE(gst_harness_push_event(h, start));
        ASSERT_TRUE(gst_harness_push_event(h, stop));
        GstSegment segment;
        gst_segment_init(&segment, GST_FORMAT_TIME);
        ASSERT_TRUE(gst_harness_push_event(h, gst_event_new_segment(&segment)));
    }
    const cv::Mat farther = frame_.depth16 * 2;
    ASSERT_EQ(gst_harness_push(e.color, bufferOf(frame_.bgr, 0)), GST_FLOW_OK);
    ASSERT_EQ(gst_harness_push(e.depth, bufferOf(farther, 0)), GST_FLOW_OK);
    GstBuffer* out = nullptr;
    while ((out = gst_harness_pull(e.color)) && GST_BUFFER_PTS(out) != 0)
        gst_buffer_unref(out);
    ASSERT_NE(out, nullptr);
    defocus::Settings settings = lensSettings();
    settings.autofocus.mode = defocus::AutofocusOptions::Mode::Follow;
    settings.autofocus.timeConstantS = 10.0;
    const cv::Mat fresh = library(settings, frame_.bgr, farther);
    defocus::Filter continued(settings);
    continued.process(frame_.bgr, frame_.depth16);
    ASSERT_FALSE(identical(fresh, continued.process(frame_.bgr, farther))) << "the two focus the same";
    EXPECT_TRUE(identical(matOf(out, frame_.bgr.size(), CV_8UC3), fresh));
}

// Defect caught: caps the element cannot use accepted (8-bit depth read as 16-bit).
TEST_F(GstDefocus, RefusesDepthThatIsNotSixteenBit)
{
    Element e(kLens);
    e.setCaps("BGR", frame_.bgr.size(), "GRAY8", frame_.depth16.size(), "BGR");
    cv::Mat depth8(frame_.depth16.size(), CV_8UC1, cv::Scalar(100));
    EXPECT_EQ(gst_harness_push(e.depth, bufferOf(depth8, 0)), GST_FLOW_NOT_NEGOTIATED);
}

// Defect caught: depth of another aspect ratio stretched over the colour instead of refused
// with the command line's message.
TEST_F(GstDefocus, DepthOfAnotherAspectRatioIsAnError)
{
    Element e(kLens);
    const cv::Size square(480, 480);
    e.setCaps("BGR", frame_.bgr.size(), "GRAY16_LE", square, "BGR");
    ASSERT_EQ(gst_harness_push(e.color, bufferOf(frame_.bgr, 0)), GST_FLOW_OK);
    gst_harness_push(e.depth, bufferOf(cv::Mat(square, CV_16UC1, cv::Scalar(5000)), 0));
    EXPECT_NE(e.error().find("aspect ratios"), std::string::npos);
}

// Defect caught: a pipeline with no depth stream stalling or crashing instead of saying so.
TEST_F(GstDefocus, NoDepthStreamIsAClearError)
{
    Element e(kLens, false);
    gst_harness_set_src_caps_str(e.color, caps("BGR", frame_.bgr.size()).c_str());
    gst_harness_set_sink_caps_str(e.color, "video/x-raw,format=BGR");
    gst_harness_push(e.color, bufferOf(frame_.bgr, 0));
    EXPECT_NE(e.error().find("No depth stream"), std::string::npos);
}

// Defect caught: the output running on a grid of one frame rate (GstVideoAggregator's) instead
// of following the colour: a gap in the timestamps filled with repeats, two close frames merged,
// or the output stamped with grid times. Three frames with a gap, variable rate: three out, each
// with its colour frame's timestamp and duration.
TEST_F(GstDefocus, IrregularTimestampsGiveOneFrameEachWithItsTimestamp)
{
    Element e(kLens);
    const std::string variable = ",framerate=0/1";
    gst_harness_set_src_caps_str(e.color, ("video/x-raw,format=BGR,width=640,height=480" + variable).c_str());
    gst_harness_set_src_caps_str(e.depth, ("video/x-raw,format=GRAY16_LE,width=640,height=480" + variable).c_str());
    gst_harness_set_sink_caps_str(e.color, "video/x-raw,format=BGR");
    const GstClockTime pts[] = {0, 36 * GST_MSECOND, 168 * GST_MSECOND};
    const GstClockTime duration[] = {36 * GST_MSECOND, 132 * GST_MSECOND, 31 * GST_MSECOND};
    for (int i = 0; i < 3; ++i) {
        for (GstHarness* h : {e.color, e.depth}) {
            GstBuffer* b = bufferOf(h == e.color ? frame_.bgr : frame_.depth16, pts[i]);
            GST_BUFFER_DURATION(b) = duration[i];
            ASSERT_EQ(gst_harness_push(h, b), GST_FLOW_OK);
        }
        GstBuffer* out = gst_harness_pull(e.color);
        ASSERT_NE(out, nullptr);
        EXPECT_EQ(GST_BUFFER_PTS(out), pts[i]) << "frame " << i;
        EXPECT_EQ(GST_BUFFER_DURATION(out), duration[i]) << "frame " << i;
        gst_buffer_unref(out);
    }
    ASSERT_TRUE(gst_harness_push_event(e.color, gst_event_new_eos()));
    ASSERT_TRUE(gst_harness_push_event(e.depth, gst_event_new_eos()));
    // Nothing but events after the three frames: no repeat fills the gap.
    EXPECT_EQ(gst_harness_try_pull(e.color), nullptr);
    GstCaps* caps = gst_pad_get_current_caps(e.color->sinkpad);
    ASSERT_NE(caps, nullptr);
    gint num = -1, den = -1;
    EXPECT_TRUE(gst_structure_get_fraction(gst_caps_get_structure(caps, 0), "framerate", &num, &den));
    EXPECT_EQ(num, 0) << "variable-rate colour must give variable-rate output";
    gst_caps_unref(caps);
}

/// Runs `pipeline` to its end and returns each buffer's (PTS, duration) at the appsinks `in` and
/// `out`, and the caps `out` had.
struct Timing {
    std::vector<std::pair<GstClockTime, GstClockTime>> in, out;
    std::string outCaps, error;
};
Timing runTimed(const std::string& description)
{
    Timing t;
    GError* error = nullptr;
    GstElement* pipeline = gst_parse_launch(description.c_str(), &error);
    if (error) {
        t.error = error->message;
        g_error_free(error);
        return t;
    }
    const auto collect = [](GstElement* sink, std::vector<std::pair<GstClockTime, GstClockTime>>& into,
                            std::string* caps) {
        while (GstSample* sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), 20 * GST_SECOND)) {
            GstBuffer* b = gst_sample_get_buffer(sample);
            into.emplace_back(GST_BUFFER_PTS(b), GST_BUFFER_DURATION(b));
            if (caps && caps->empty()) {
                gchar* text = gst_caps_to_string(gst_sample_get_caps(sample));
                *caps = text;
                g_free(text);
            }
            gst_sample_unref(sample);
        }
    };
    GstElement* in = gst_bin_get_by_name(GST_BIN(pipeline), "in");
    GstElement* out = gst_bin_get_by_name(GST_BIN(pipeline), "out");
    gst_element_set_state(pipeline, GST_STATE_PLAYING);
    // Both appsinks hold every sample until pulled (max-buffers=0): drain `out` on another thread.
    std::thread drainOut([&] { collect(out, t.out, &t.outCaps); });
    collect(in, t.in, nullptr);
    drainOut.join();
    GstBus* bus = gst_element_get_bus(pipeline);
    if (GstMessage* m = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR)) {
        GError* err = nullptr;
        gst_message_parse_error(m, &err, nullptr);
        t.error = err->message;
        g_error_free(err);
        gst_message_unref(m);
    }
    gst_object_unref(bus);
    gst_element_set_state(pipeline, GST_STATE_NULL);
    gst_object_unref(in);
    gst_object_unref(out);
    gst_object_unref(pipeline);
    return t;
}

// Defect caught: defocussrc declaring a mean rate for a recording with gaps (the aggregator then
// repeats frames into the gaps: 36 frames out for 30 in), or either element changing the
// timestamps: the bundled clip with frames taken out of rgb.txt, through defocussrc ! defocus,
// gives as many frames as the colour pad carried, each with its PTS and duration, variable rate,
// and the PTS are the capture times of rgb.txt from the first.
TEST_F(GstDefocus, ClipWithGapsThroughDefocussrcKeepsEveryFrameAndTimestamp)
{
    namespace fs = std::filesystem;
    const fs::path clip = fs::path(DEFOCUS_DATA_DIR) / "tum_fr1_rpy";
    const fs::path dir = fs::temp_directory_path() / ("defocus-gaps-" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::create_directory_symlink(clip / "rgb", dir / "rgb");
    fs::create_directory_symlink(clip / "depth", dir / "depth");
    fs::copy_file(clip / "depth.txt", dir / "depth.txt");
    // rgb.txt without its 3rd, 4th and 8th frames: gaps of two and one frames.
    std::ifstream rgbIn(clip / "rgb.txt");
    std::ofstream rgbOut(dir / "rgb.txt");
    std::vector<double> kept;
    int index = 0;
    for (std::string line; std::getline(rgbIn, line);) {
        if (line.empty() || line[0] == '#') {
            rgbOut << line << "\n";
            continue;
        }
        if (index != 2 && index != 3 && index != 7) {
            rgbOut << line << "\n";
            kept.push_back(std::stod(line));
        }
        ++index;
    }
    rgbOut.close();
    const Timing t = runTimed("defocussrc name=s location=" + dir.string() + " depth-scale=5000 "
                              "defocus name=d autofocus=false focus=1.0 depth-scale=5000 ! appsink name=out sync=false "
                              "s.color ! tee name=t ! queue ! d.color t. ! queue ! appsink name=in sync=false "
                              "s.depth ! queue ! d.depth");
    fs::remove_all(dir);
    ASSERT_EQ(t.error, "");
    ASSERT_EQ(t.in.size(), kept.size());
    EXPECT_EQ(t.out, t.in);
    for (std::size_t i = 0; i < t.in.size(); ++i) {
        const auto expected = static_cast<GstClockTime>(std::llround((kept[i] - kept[0]) * GST_SECOND));
        EXPECT_EQ(t.in[i].first, expected) << "frame " << i;
        if (i + 1 < t.in.size()) {
            const auto next = static_cast<GstClockTime>(std::llround((kept[i + 1] - kept[0]) * GST_SECOND));
            EXPECT_EQ(t.in[i].second, next - expected) << "frame " << i << " does not last until the next";
        }
    }
    EXPECT_NE(t.outCaps.find("framerate=(fraction)0/1"), std::string::npos) << t.outCaps;
}

// Defect caught: only a depth stream linked leaving the pipeline in PREROLLING for ever (the
// base class waiting for caps from a colour pad that does not exist) instead of saying so.
TEST_F(GstDefocus, NoColourStreamIsAClearError)
{
    GstElement* element = gst_element_factory_make("defocus", nullptr);
    ASSERT_NE(element, nullptr);
    GstBus* bus = gst_bus_new();
    gst_element_set_bus(element, bus);
    GstHarness* depth = gst_harness_new_with_element(element, "depth", "src");
    gst_harness_set_live(depth, FALSE);
    gst_harness_set_src_caps_str(depth, caps("GRAY16_LE", frame_.depth16.size()).c_str());
    gst_harness_push(depth, bufferOf(frame_.depth16, 0));
    GstMessage* message = gst_bus_timed_pop_filtered(bus, 10 * GST_SECOND, GST_MESSAGE_ERROR);
    ASSERT_NE(message, nullptr) << "no error within 10 s";
    GError* err = nullptr;
    gst_message_parse_error(message, &err, nullptr);
    EXPECT_NE(std::string(err->message).find("No colour stream"), std::string::npos) << err->message;
    g_error_free(err);
    gst_message_unref(message);
    gst_harness_teardown(depth);
    gst_object_unref(element);
    gst_object_unref(bus);
}

// Defect caught: a property range narrower than the command line's option (autofocus-time-constant
// stopping at 10 while `--tau 20` runs, near stopping short of inf where far takes it,
// depth-scale starting at 1 on defocussrc): values the command line takes are refused (GLib
// warns and keeps the old value). The library's check() takes the same values.
TEST_F(GstDefocus, PropertiesTakeWhatTheCommandLineTakes)
{
    const std::pair<const char*, const char*> filterValues[] = {
        {"autofocus-time-constant", "20"}, {"near", "inf"}, {"far", "inf"}, {"depth-scale", "0.0005"},
        {"focus", "inf"}, {"f-number", "0.7"}, {"focal-length", "1200"}, {"max-coc", "512"}};
    const std::pair<const char*, const char*> sourceValues[] = {
        {"depth-scale", "0.5"}, {"input-depth-scale", "0.5"}, {"fps", "2000"}, {"width", "20000"}};
    for (const auto& [element, values] :
         {std::pair{"defocus", std::vector(std::begin(filterValues), std::end(filterValues))},
          std::pair{"defocussrc", std::vector(std::begin(sourceValues), std::end(sourceValues))}}) {
        GstElement* e = gst_element_factory_make(element, nullptr);
        ASSERT_NE(e, nullptr);
        for (const auto& [name, text] : values) {
            GValue expected = G_VALUE_INIT, got = G_VALUE_INIT;
            GParamSpec* spec = g_object_class_find_property(G_OBJECT_GET_CLASS(e), name);
            ASSERT_NE(spec, nullptr) << name;
            g_value_init(&expected, spec->value_type);
            ASSERT_TRUE(gst_value_deserialize(&expected, text)) << name;
            EXPECT_FALSE(g_param_value_validate(spec, &expected)) << element << " " << name << "=" << text
                                                                 << " is outside the property's range";
            gst_util_set_object_arg(G_OBJECT(e), name, text);
            g_value_init(&got, spec->value_type);
            g_object_get_property(G_OBJECT(e), name, &got);
            EXPECT_EQ(gst_value_compare(&got, &expected), GST_VALUE_EQUAL) << element << " " << name << "=" << text;
            g_value_unset(&expected);
            g_value_unset(&got);
        }
        gst_object_unref(e);
    }
    defocus::Settings settings;
    settings.autofocus.timeConstantS = 20.0;
    settings.depthScale = 0.0005;
    EXPECT_TRUE(defocus::check(settings).empty());
}

// Defect caught: a live pipeline that stalls (the element waiting for data a live source gives
// only in time), or that reports no latency of its own, so that a live sink drops every frame.
TEST_F(GstDefocus, LiveSourcesFlowAndLatencyIsReported)
{
    GError* error = nullptr;
    GstElement* pipeline = gst_parse_launch(
        "defocus name=d autofocus=false focus=1.0 post-timings=true ! fakesink sync=true "
        "videotestsrc is-live=true ! video/x-raw,format=BGR,width=160,height=120,framerate=30/1 ! d.color "
        "videotestsrc is-live=true pattern=solid-color foreground-color=0xff404040 "
        "! video/x-raw,format=GRAY16_LE,width=160,height=120,framerate=30/1 ! d.depth",
        &error);
    ASSERT_EQ(error, nullptr) << error->message;
    GstBus* bus = gst_element_get_bus(pipeline);
    ASSERT_NE(gst_element_set_state(pipeline, GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
    int frames = 0;
    while (frames < 10) {
        GstMessage* message =
            gst_bus_timed_pop_filtered(bus, 10 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_ELEMENT | GST_MESSAGE_ERROR));
        ASSERT_NE(message, nullptr) << "no frame for 10 s after " << frames;
        ASSERT_NE(GST_MESSAGE_TYPE(message), GST_MESSAGE_ERROR);
        frames += gst_structure_has_name(gst_message_get_structure(message), "defocus-timings") ? 1 : 0;
        gst_message_unref(message);
    }
    GstQuery* query = gst_query_new_latency();
    ASSERT_TRUE(gst_element_query(pipeline, query));
    gboolean live = FALSE;
    GstClockTime min = 0, max = 0;
    gst_query_parse_latency(query, &live, &min, &max);
    EXPECT_TRUE(live);
    // videotestsrc's own frame, and the element's (one output frame to filter in).
    EXPECT_GE(min, 2 * kFrame);
    gst_query_unref(query);
    gst_element_set_state(pipeline, GST_STATE_NULL);
    gst_object_unref(bus);
    gst_object_unref(pipeline);
}

// ---- GL memory ----------------------------------------------------------------------------------

/// Counts the maps of GL memory for the CPU (without GST_MAP_GL) anywhere in the process while it
/// lives, through the map function of the class of `context`'s default GL memory allocator (the
/// one GL buffer pools use).
class CpuMapsOfGlMemory {
public:
    explicit CpuMapsOfGlMemory(GstGLContext* context)
    {
        GstGLMemoryAllocator* allocator = gst_gl_memory_allocator_get_default(context);
        klass_ = GST_GL_BASE_MEMORY_ALLOCATOR_GET_CLASS(allocator);
        gst_object_unref(allocator);
        original() = klass_->map;
        klass_->map = counting;
        count() = 0;
    }
    ~CpuMapsOfGlMemory() { klass_->map = original(); }
    CpuMapsOfGlMemory(const CpuMapsOfGlMemory&) = delete;
    CpuMapsOfGlMemory& operator=(const CpuMapsOfGlMemory&) = delete;
    int operator()() const { return count(); }

private:
    static gpointer counting(GstGLBaseMemory* memory, GstMapInfo* info, gsize size)
    {
        if ((info->flags & GST_MAP_GL) == 0)
            ++count();
        return original()(memory, info, size);
    }
    static std::atomic<int>& count()
    {
        static std::atomic<int> n{0};
        return n;
    }
    static GstGLBaseMemoryAllocatorMapFunction& original()
    {
        static GstGLBaseMemoryAllocatorMapFunction function = nullptr;
        return function;
    }
    GstGLBaseMemoryAllocatorClass* klass_ = nullptr;
};

/// A GL context of the test's own on the library's headless EGL display (no window system needed),
/// given to an element as the application's.
struct GlContext {
    GstGLDisplay* display = nullptr;
    GstGLContext* context = nullptr;
    std::string why; ///< empty when made

    GlContext()
    {
        try {
            display = GST_GL_DISPLAY(gst_gl_display_egl_new_with_egl_display(defocus::eglDisplay()));
        } catch (const defocus::GlError& error) {
            why = error.what();
            return;
        }
        gst_gl_display_filter_gl_api(display, GST_GL_API_OPENGL3);
        GError* error = nullptr;
        if (!gst_gl_display_create_context(display, nullptr, &context, &error)) {
            why = error ? error->message : "no GL context";
            g_clear_error(&error);
            return;
        }
        gst_gl_display_add_context(display, context);
    }
    ~GlContext()
    {
        gst_clear_object(&context);
        gst_clear_object(&display);
    }
    void give(GstElement* element) const
    {
        GstContext* shared = gst_context_new(GST_GL_DISPLAY_CONTEXT_TYPE, TRUE);
        gst_context_set_gl_display(shared, display);
        gst_element_set_context(element, shared);
        gst_context_unref(shared);
        GstContext* app = gst_context_new("gst.gl.app_context", TRUE);
        gst_structure_set(gst_context_writable_structure(app), "context", GST_TYPE_GL_CONTEXT, context, nullptr);
        gst_element_set_context(element, app);
        gst_context_unref(app);
    }
    /// A buffer of GL memory of `caps` holding `image` (tightly packed rows), uploaded on its
    /// first map for GL.
    GstBuffer* buffer(const std::string& caps, const cv::Mat& image, GstClockTime pts) const
    {
        GstCaps* parsed = gst_caps_from_string(caps.c_str());
        GstVideoInfo info;
        gst_video_info_from_caps(&info, parsed);
        GstBufferPool* pool = gst_gl_buffer_pool_new(context);
        GstStructure* config = gst_buffer_pool_get_config(pool);
        gst_buffer_pool_config_set_params(config, parsed, static_cast<guint>(info.size), 1, 1);
        gst_buffer_pool_set_config(pool, config);
        gst_buffer_pool_set_active(pool, TRUE);
        GstBuffer* buffer = nullptr;
        gst_buffer_pool_acquire_buffer(pool, &buffer, nullptr);
        GstVideoFrame frame;
        if (buffer && gst_video_frame_map(&frame, &info, buffer, GST_MAP_WRITE)) {
            const auto row = static_cast<size_t>(image.cols) * image.elemSize();
            for (int y = 0; y < image.rows; ++y)
                std::memcpy(static_cast<guint8*>(GST_VIDEO_FRAME_PLANE_DATA(&frame, 0)) +
                                y * GST_VIDEO_FRAME_PLANE_STRIDE(&frame, 0),
                            image.ptr(y), row);
            gst_video_frame_unmap(&frame);
        }
        // The buffer outlives its pool's activity (a copy of the reference, not the pool's).
        GstBuffer* copy = buffer ? gst_buffer_copy_deep(buffer) : nullptr;
        if (buffer)
            gst_buffer_unref(buffer);
        gst_buffer_pool_set_active(pool, FALSE);
        gst_object_unref(pool);
        gst_caps_unref(parsed);
        if (copy) {
            GST_BUFFER_PTS(copy) = pts;
            GST_BUFFER_DURATION(copy) = kFrame;
        }
        return copy;
    }
};

std::string glCaps(const char* format, cv::Size size)
{
    return "video/x-raw(memory:GLMemory),format=" + std::string(format) + ",width=" + std::to_string(size.width) +
           ",height=" + std::to_string(size.height) + ",framerate=30/1,texture-target=2D";
}

// Defects caught: the element mapping a GL frame for the CPU (a download of the colour, depth or
// output, as the system-memory path's gst_video_frame_map would do), an output without a sync
// point for the next element, or GL memory filtered into another image than the library's.
TEST_F(GstDefocus, GlMemoryInAndOutIsNeverMappedForTheCpu)
{
    const GlContext gl;
    if (!gl.why.empty())
        GTEST_SKIP() << "no GL context for GStreamer: " << gl.why;
    Element e(kLens);
    gl.give(e.element);
    const std::string colorCaps = glCaps("BGRA", frame_.bgr.size());
    gst_harness_set_src_caps_str(e.color, colorCaps.c_str());
    const std::string depthCaps = glCaps("GRAY16_LE", frame_.depth16.size());
    gst_harness_set_src_caps_str(e.depth, depthCaps.c_str());
    gst_harness_set_sink_caps_str(e.color, "video/x-raw(memory:GLMemory),format=RGBA,texture-target=2D");
    cv::Mat bgra;
    cv::cvtColor(frame_.bgr, bgra, cv::COLOR_BGR2BGRA);
    std::vector<GstBuffer*> colour, depth;
    for (int i = 0; i < 2; ++i) {
        colour.push_back(gl.buffer(colorCaps, bgra, i * kFrame));
        depth.push_back(gl.buffer(depthCaps, frame_.depth16, i * kFrame));
        ASSERT_TRUE(colour.back() && depth.back());
    }

    const CpuMapsOfGlMemory cpuMaps(gl.context);
    std::vector<GstBuffer*> out;
    for (int i = 0; i < 2; ++i) {
        ASSERT_EQ(gst_harness_push(e.color, colour[static_cast<size_t>(i)]), GST_FLOW_OK);
        ASSERT_EQ(gst_harness_push(e.depth, depth[static_cast<size_t>(i)]), GST_FLOW_OK);
        out.push_back(gst_harness_pull(e.color));
        ASSERT_NE(out.back(), nullptr);
    }
    EXPECT_EQ(cpuMaps(), 0) << "the element mapped GL memory for the CPU";
    for (int i = 0; i < 2; ++i) {
        GstBuffer* buffer = out[static_cast<size_t>(i)];
        EXPECT_EQ(GST_BUFFER_PTS(buffer), i * kFrame);
        ASSERT_TRUE(gst_buffer_n_memory(buffer) > 0 && gst_is_gl_memory(gst_buffer_peek_memory(buffer, 0)));
        // A fence (GLsync) in the sync meta: a meta the pool added and nobody set has none.
        const GstGLSyncMeta* sync = gst_buffer_get_gl_sync_meta(buffer);
        EXPECT_TRUE(sync && sync->data) << "no sync point on the output";
        // Read back here, by the test (a map the counter sees: it counts).
        GstVideoInfo info;
        gst_video_info_set_format(&info, GST_VIDEO_FORMAT_RGBA, static_cast<guint>(frame_.bgr.cols),
                                  static_cast<guint>(frame_.bgr.rows));
        GstVideoFrame frame;
        ASSERT_TRUE(gst_video_frame_map(&frame, &info, buffer, GST_MAP_READ));
        const cv::Mat rgba(frame_.bgr.rows, frame_.bgr.cols, CV_8UC4, GST_VIDEO_FRAME_PLANE_DATA(&frame, 0),
                           static_cast<size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(&frame, 0)));
        cv::Mat bgr;
        cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
        gst_video_frame_unmap(&frame);
        EXPECT_TRUE(identical(bgr, library(lensSettings(), frame_.bgr, frame_.depth16))) << "frame " << i;
        gst_buffer_unref(buffer);
    }
    EXPECT_GE(cpuMaps(), 2) << "the counter does not see maps for the CPU";
}

} // namespace

int main(int argc, char** argv)
{
    // The plugin of this build, with a registry of its own (not the user's).
    g_setenv("GST_PLUGIN_PATH", DEFOCUS_GST_PLUGIN_DIR, TRUE);
    g_setenv("GST_REGISTRY", DEFOCUS_GST_PLUGIN_DIR "/registry.bin", TRUE);
    gst_init(&argc, &argv);
    ::testing::InitGoogleTest(&argc, argv);
    return RUN_ALL_TESTS();
}
