// SPDX-License-Identifier: LGPL-2.1-or-later
// Streams without a camera: V4L2 pixel format conversions against hand-computed values, a video
// clip the test writes itself, depth from another source paired by index and by timestamp, and
// the errors of camera paths that are no cameras. Capture from real drivers: tests/v4l2_vm_probe.cpp.
#include <algorithm>
#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "defocus/Filter.hpp"
#include "sources/FrameSource.hpp"
#include "sources/PairedSource.hpp"
#include "sources/V4l2Formats.hpp"
#include "sources/V4l2Source.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

cv::Vec3b at(const cv::Mat& bgr, int x, int y)
{
    return bgr.at<cv::Vec3b>(y, x);
}

/// Each channel of `got` within `tolerance` of `want` (B, G, R).
::testing::AssertionResult near(const cv::Vec3b& got, const cv::Vec3b& want, int tolerance)
{
    for (int c = 0; c < 3; ++c)
        if (std::abs(int(got[c]) - int(want[c])) > tolerance)
            return ::testing::AssertionFailure() << "got BGR (" << int(got[0]) << ", " << int(got[1])
                                                 << ", " << int(got[2]) << "), want (" << int(want[0])
                                                 << ", " << int(want[1]) << ", " << int(want[2]) << ")";
    return ::testing::AssertionSuccess();
}

// Expected colours, BT.601 limited range (Y 16-235, Cb/Cr 16-240 around 128):
//   R = 1.164 (Y-16) + 1.596 (Cr-128)
//   G = 1.164 (Y-16) - 0.813 (Cr-128) - 0.391 (Cb-128)
//   B = 1.164 (Y-16) + 2.018 (Cb-128)
// Y=16 Cb=Cr=128 -> 0 0 0;  Y=235 -> 1.164 * 219 = 254.9 -> 255;  Y=126 -> 128.0
// Y=81  Cb=90  Cr=240 (red):   R = 75.7 + 178.8 = 254.4, G = 75.7 - 91.1 + 14.9 = -0.5, B = 75.7 - 76.7 = -1.0
// Y=41  Cb=240 Cr=110 (blue):  R = 29.1 - 28.7 = 0.4,   G = 29.1 + 14.6 - 43.8 = -0.1, B = 29.1 + 226.0 = 255.1
// Y=145 Cb=54  Cr=34  (green): R = 150.2 - 150.0 = 0.2, G = 150.2 + 76.4 + 28.9 = 255.5, B = 150.2 - 149.3 = 0.9
// OpenCV computes in 20-bit fixed point, so each channel may differ from these by 1; allow 2.
constexpr int yuvTolerance = 2;
const cv::Vec3b black(0, 0, 0), white(255, 255, 255), grey128(128, 128, 128);
const cv::Vec3b red(0, 0, 254), blue(255, 0, 0), green(1, 255, 0);

TEST(V4l2Formats, FourccNames)
{
    EXPECT_EQ(v4l2::fourccName(V4L2_PIX_FMT_YUYV), "YUYV");
    EXPECT_EQ(v4l2::fourccName(V4L2_PIX_FMT_Z16), "Z16 ");
    EXPECT_EQ(v4l2::fourccName(0x01020304u), "????");
    EXPECT_EQ(v4l2::fourccFromName("MJPG"), V4L2_PIX_FMT_MJPEG);
    EXPECT_EQ(v4l2::fourccFromName("Z16"), V4L2_PIX_FMT_Z16); // padded with a space
    EXPECT_EQ(v4l2::fourccFromName("RGB3"), V4L2_PIX_FMT_RGB24);
    EXPECT_EQ(v4l2::fourccFromName(""), 0u);
    EXPECT_EQ(v4l2::fourccFromName("MJPEG"), 0u);
    EXPECT_TRUE(v4l2::isColorFormat(V4L2_PIX_FMT_NV12));
    EXPECT_FALSE(v4l2::isColorFormat(V4L2_PIX_FMT_Z16));
    EXPECT_TRUE(v4l2::isDepthFormat(V4L2_PIX_FMT_Z16));
    EXPECT_FALSE(v4l2::isDepthFormat(V4L2_PIX_FMT_Y16));
}

TEST(V4l2Formats, FrameSizes)
{
    EXPECT_EQ(v4l2::minimumFrameBytes({V4L2_PIX_FMT_YUYV, 640, 480, 0}), 640u * 480 * 2);
    EXPECT_EQ(v4l2::minimumFrameBytes({V4L2_PIX_FMT_YUYV, 640, 480, 1536}), 1536u * 480);
    EXPECT_EQ(v4l2::minimumFrameBytes({V4L2_PIX_FMT_NV12, 640, 480, 0}), 640u * 720);
    EXPECT_EQ(v4l2::minimumFrameBytes({V4L2_PIX_FMT_RGB24, 4, 2, 0}), 24u);
    EXPECT_EQ(v4l2::minimumFrameBytes({V4L2_PIX_FMT_Z16, 3, 2, 8}), 16u);
    EXPECT_EQ(v4l2::minimumFrameBytes({V4L2_PIX_FMT_MJPEG, 640, 480, 0}), 0u);
}

TEST(V4l2Formats, YuyvWithRowPadding)
{
    // 4x2 pixels, 8 bytes of pixels and 4 bytes of padding (0xEE, must be ignored) per row.
    const Bytes data = {16,  128, 235, 128, 81,  90, 81,  240, 0xEE, 0xEE, 0xEE, 0xEE,
                        41,  240, 41,  110, 145, 54, 145, 34,  0xEE, 0xEE, 0xEE, 0xEE};
    const cv::Mat bgr = v4l2::convertYuyv(data, 4, 2, 12);
    ASSERT_EQ(bgr.size(), cv::Size(4, 2));
    ASSERT_EQ(bgr.type(), CV_8UC3);
    EXPECT_TRUE(near(at(bgr, 0, 0), black, yuvTolerance));
    EXPECT_TRUE(near(at(bgr, 1, 0), white, yuvTolerance));
    EXPECT_TRUE(near(at(bgr, 2, 0), red, yuvTolerance));
    EXPECT_TRUE(near(at(bgr, 3, 0), red, yuvTolerance));
    EXPECT_TRUE(near(at(bgr, 0, 1), blue, yuvTolerance));
    EXPECT_TRUE(near(at(bgr, 2, 1), green, yuvTolerance));

    EXPECT_TRUE(v4l2::convertYuyv(std::span(data).first(23), 4, 2, 12).empty()) << "short data";
    EXPECT_TRUE(v4l2::convertYuyv(data, 3, 2, 12).empty()) << "odd width";
    // The dispatcher gives the same image.
    const cv::Mat dispatched = v4l2::convert(data, {V4L2_PIX_FMT_YUYV, 4, 2, 12});
    EXPECT_EQ(cv::norm(dispatched, bgr, cv::NORM_INF), 0.0);
}

TEST(V4l2Formats, CapturedYuvKeepsThePlanesAsTheFilterReadsThem)
{
    // Catches a camera's Y'CbCr kept for the GPU (SourceSettings::yuvColor) other than the BGR it
    // gave before: the driver's row padding read as pixels, NV12's chroma rows taken from the
    // wrong offset, the layout or the matrix mislabelled (yuvToBgr() then differs from the CPU
    // conversion by more than its one level of rounding), or planes that still view the capture
    // buffer, which the driver fills again once it is queued.
    Bytes yuyv = {16, 128, 235, 128, 81, 90, 81, 240, 0xEE, 0xEE, 0xEE, 0xEE,
                  41, 240, 41, 110, 145, 54, 145, 34, 0xEE, 0xEE, 0xEE, 0xEE};
    Bytes nv12 = {16, 235, 81, 81, 0xEE, 0xEE, 126, 126, 81, 81, 0xEE, 0xEE, 128, 128, 90, 240, 0xEE, 0xEE};
    struct Case {
        const char* name;
        Bytes* data;
        v4l2::PixelLayout layout;
        YuvImage::Layout expected;
    };
    for (const Case& c : {Case{"YUYV", &yuyv, {V4L2_PIX_FMT_YUYV, 4, 2, 12}, YuvImage::Layout::Yuyv},
                          Case{"NV12", &nv12, {V4L2_PIX_FMT_NV12, 4, 2, 6}, YuvImage::Layout::Nv12}}) {
        const cv::Mat bgr = v4l2::convert(*c.data, c.layout);
        const std::optional<YuvImage> yuv = v4l2::capturedYuv(*c.data, c.layout);
        ASSERT_TRUE(yuv) << c.name;
        EXPECT_EQ(yuv->layout, c.expected) << c.name;
        EXPECT_EQ(yuv->matrix, YuvImage::Matrix::Bt601) << c.name;
        EXPECT_EQ(yuv->range, YuvImage::Range::Limited) << c.name;
        ASSERT_EQ(yuv->y.size(), cv::Size(4, 2)) << c.name;
        const cv::Mat fromPlanes = yuvToBgr(*yuv);
        EXPECT_LE(cv::norm(fromPlanes, bgr, cv::NORM_INF), 1.0) << c.name << ": " << fromPlanes << " against " << bgr;
        std::fill(c.data->begin(), c.data->end(), std::uint8_t{0x55}); // the driver fills the buffer again
        EXPECT_EQ(cv::norm(yuvToBgr(*yuv), fromPlanes, cv::NORM_INF), 0.0) << c.name << ": the planes view the buffer";
    }
    EXPECT_FALSE(v4l2::capturedYuv(std::span(yuyv).first(23), {V4L2_PIX_FMT_YUYV, 4, 2, 12})) << "short data";
    EXPECT_FALSE(v4l2::capturedYuv(yuyv, {V4L2_PIX_FMT_YUYV, 3, 2, 12})) << "odd width";
    EXPECT_FALSE(v4l2::capturedYuv(std::span(nv12).first(17), {V4L2_PIX_FMT_NV12, 4, 2, 6})) << "short data";
    EXPECT_FALSE(v4l2::capturedYuv(nv12, {V4L2_PIX_FMT_NV12, 4, 1, 6})) << "odd height";
    EXPECT_FALSE(v4l2::capturedYuv(yuyv, {V4L2_PIX_FMT_RGB24, 4, 2, 12})) << "not Y'CbCr";
}

TEST(V4l2Formats, CapturedYuvKeepsTheDriversEncoding)
{
    // Catches the driver's stated encoding lost on the way to the filter: an HD webcam's BT.709 or
    // a full-range (JPEG) stream read as BT.601 limited range tints and flattens its colours; and
    // V4L2's defaults resolved otherwise than the kernel resolves them.
    using M = YuvImage::Matrix;
    using R = YuvImage::Range;
    struct Case {
        std::uint32_t colorspace, ycbcr, quantization;
        M matrix;
        R range;
        bool supported;
    };
    const Case cases[] = {
        {V4L2_COLORSPACE_SMPTE170M, V4L2_YCBCR_ENC_DEFAULT, V4L2_QUANTIZATION_DEFAULT, M::Bt601, R::Limited, true},
        {V4L2_COLORSPACE_SRGB, V4L2_YCBCR_ENC_DEFAULT, V4L2_QUANTIZATION_DEFAULT, M::Bt601, R::Limited, true},
        {V4L2_COLORSPACE_REC709, V4L2_YCBCR_ENC_DEFAULT, V4L2_QUANTIZATION_DEFAULT, M::Bt709, R::Limited, true},
        {V4L2_COLORSPACE_JPEG, V4L2_YCBCR_ENC_DEFAULT, V4L2_QUANTIZATION_DEFAULT, M::Bt601, R::Full, true},
        {V4L2_COLORSPACE_SRGB, V4L2_YCBCR_ENC_709, V4L2_QUANTIZATION_FULL_RANGE, M::Bt709, R::Full, true},
        {V4L2_COLORSPACE_REC709, V4L2_YCBCR_ENC_601, V4L2_QUANTIZATION_LIM_RANGE, M::Bt601, R::Limited, true},
        {V4L2_COLORSPACE_BT2020, V4L2_YCBCR_ENC_DEFAULT, V4L2_QUANTIZATION_DEFAULT, M::Bt601, R::Limited, false},
    };
    for (const Case& c : cases) {
        const v4l2::YuvEncoding e = v4l2::yuvEncoding(c.colorspace, c.ycbcr, c.quantization);
        EXPECT_EQ(e.matrix, c.matrix) << c.colorspace << " " << c.ycbcr << " " << c.quantization;
        EXPECT_EQ(e.range, c.range) << c.colorspace << " " << c.ycbcr << " " << c.quantization;
        EXPECT_EQ(e.supported, c.supported) << c.colorspace << " " << c.ycbcr << " " << c.quantization;
    }
    // The planes carry it: BT.709 full range makes other colours of the same bytes.
    const Bytes yuyv = {16, 128, 235, 128, 81, 90, 81, 240, 41, 240, 41, 110, 145, 54, 145, 34};
    v4l2::PixelLayout layout{V4L2_PIX_FMT_YUYV, 4, 2, 0};
    const std::optional<YuvImage> sd = v4l2::capturedYuv(yuyv, layout);
    layout.matrix = M::Bt709;
    layout.range = R::Full;
    const std::optional<YuvImage> hd = v4l2::capturedYuv(yuyv, layout);
    ASSERT_TRUE(sd && hd);
    EXPECT_EQ(hd->matrix, M::Bt709);
    EXPECT_EQ(hd->range, R::Full);
    EXPECT_GT(cv::norm(yuvToBgr(*hd), yuvToBgr(*sd), cv::NORM_INF), 10.0);
}

TEST(V4l2Formats, Nv12)
{
    // 4x2 pixels, stride 6: the Y rows, then one row of interleaved Cb,Cr for the two 2x2 blocks.
    const Bytes data = {16,  235, 81, 81, 0xEE, 0xEE, //
                        126, 126, 81, 81, 0xEE, 0xEE, //
                        128, 128, 90, 240, 0xEE, 0xEE};
    const cv::Mat bgr = v4l2::convertNv12(data, 4, 2, 6);
    ASSERT_EQ(bgr.size(), cv::Size(4, 2));
    EXPECT_TRUE(near(at(bgr, 0, 0), black, yuvTolerance));
    EXPECT_TRUE(near(at(bgr, 1, 0), white, yuvTolerance));
    EXPECT_TRUE(near(at(bgr, 0, 1), grey128, yuvTolerance));
    for (int y = 0; y < 2; ++y)
        for (int x = 2; x < 4; ++x)
            EXPECT_TRUE(near(at(bgr, x, y), red, yuvTolerance)) << x << "," << y;
    EXPECT_TRUE(v4l2::convertNv12(std::span(data).first(17), 4, 2, 6).empty()) << "short data";
    EXPECT_TRUE(v4l2::convertNv12(data, 4, 1, 6).empty()) << "odd height";
}

TEST(V4l2Formats, Rgb24AndBgr24)
{
    const Bytes data = {10, 20, 30, 40, 50, 60};
    const cv::Mat fromRgb = v4l2::convertRgb24(data, 2, 1, 0, false);
    ASSERT_EQ(fromRgb.size(), cv::Size(2, 1));
    EXPECT_EQ(at(fromRgb, 0, 0), cv::Vec3b(30, 20, 10));
    EXPECT_EQ(at(fromRgb, 1, 0), cv::Vec3b(60, 50, 40));
    const cv::Mat fromBgr = v4l2::convertRgb24(data, 2, 1, 0, true);
    EXPECT_EQ(at(fromBgr, 0, 0), cv::Vec3b(10, 20, 30));
    EXPECT_EQ(at(fromBgr, 1, 0), cv::Vec3b(40, 50, 60));
    EXPECT_NE(static_cast<const void*>(fromBgr.data), static_cast<const void*>(data.data()))
        << "the frame must own its pixels, not alias the capture buffer";
}

TEST(V4l2Formats, Grey)
{
    const Bytes data = {0, 77, 255, 0xEE};
    const cv::Mat bgr = v4l2::convertGrey(data, 3, 1, 4);
    ASSERT_EQ(bgr.size(), cv::Size(3, 1));
    EXPECT_EQ(at(bgr, 0, 0), cv::Vec3b(0, 0, 0));
    EXPECT_EQ(at(bgr, 1, 0), cv::Vec3b(77, 77, 77));
    EXPECT_EQ(at(bgr, 2, 0), cv::Vec3b(255, 255, 255));
}

TEST(V4l2Formats, Z16KeepsItsUnitsWhichAFrameTurnsIntoMetres)
{
    // 3x2 little-endian 16-bit values, stride 8 bytes (2 bytes of padding per row).
    const std::vector<std::uint16_t> values = {0, 1, 1000, 0xEEEE, 1500, 65535, 5000, 0xEEEE};
    Bytes data;
    for (const std::uint16_t v : values) {
        data.push_back(static_cast<std::uint8_t>(v & 0xFF));
        data.push_back(static_cast<std::uint8_t>(v >> 8));
    }
    Frame frame;
    frame.depth = v4l2::convertZ16(data, 3, 2, 8);
    ASSERT_EQ(frame.depth.size(), cv::Size(3, 2));
    ASSERT_EQ(frame.depth.type(), CV_16UC1);
    EXPECT_EQ(frame.depth.at<std::uint16_t>(1, 1), 65535) << "little-endian, each row after its stride";
    EXPECT_EQ(frame.depth.at<std::uint16_t>(1, 2), 5000);
    data[2] = 7; // the camera's buffer goes back to the driver: the frame owns a copy
    EXPECT_EQ(frame.depth.at<std::uint16_t>(0, 1), 1);
    frame.depthScale = 1000.0;
    const cv::Mat mm = depthMetres(frame);
    ASSERT_EQ(mm.type(), CV_32FC1);
    EXPECT_EQ(mm.at<float>(0, 0), 0.0f) << "0 stays 'no measurement'";
    EXPECT_FLOAT_EQ(mm.at<float>(0, 1), 0.001f);
    EXPECT_FLOAT_EQ(mm.at<float>(0, 2), 1.0f);
    EXPECT_FLOAT_EQ(mm.at<float>(1, 0), 1.5f);
    EXPECT_FLOAT_EQ(mm.at<float>(1, 1), 65.535f);
    EXPECT_FLOAT_EQ(mm.at<float>(1, 2), 5.0f);
    frame.depthScale = 5000.0;
    EXPECT_FLOAT_EQ(depthMetres(frame).at<float>(1, 2), 1.0f);
    EXPECT_TRUE(v4l2::convertZ16(std::span(data).first(15), 3, 2, 8).empty());
}

TEST(V4l2Formats, MjpegDecodesWithTrailingBytes)
{
    cv::Mat image(16, 32, CV_8UC3, cv::Scalar(40, 120, 200));
    image(cv::Rect(0, 0, 16, 16)).setTo(cv::Scalar(250, 250, 250));
    std::vector<std::uint8_t> jpeg;
    ASSERT_TRUE(cv::imencode(".jpg", image, jpeg));
    const cv::Mat reference = cv::imdecode(jpeg, cv::IMREAD_COLOR);

    const cv::Mat decoded = v4l2::convertMjpeg(jpeg);
    ASSERT_EQ(decoded.size(), image.size());
    EXPECT_EQ(cv::norm(decoded, reference, cv::NORM_INF), 0.0);
    // A driver may report the whole buffer as used (v4l2loopback's first MJPG buffer does).
    Bytes padded = jpeg;
    padded.resize(jpeg.size() + 4096, 0);
    EXPECT_EQ(cv::norm(v4l2::convertMjpeg(padded), reference, cv::NORM_INF), 0.0);

    EXPECT_TRUE(v4l2::convertMjpeg(Bytes(100, 0)).empty()) << "no JPEG start marker";
    EXPECT_TRUE(v4l2::convertMjpeg(std::span(jpeg).first(2)).empty());
}

// ---- video file and depth from another source ----

constexpr int clipWidth = 64, clipHeight = 48, clipFrames = 12;
constexpr double clipFps = 10.0;

/// A clip of 12 frames of 64x48 at 10 Hz; frame k is filled with grey 20*k.
fs::path writeClip(const fs::path& dir)
{
    const fs::path clip = dir / "clip.avi";
    cv::VideoWriter writer(clip.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), clipFps,
                           cv::Size(clipWidth, clipHeight));
    EXPECT_TRUE(writer.isOpened());
    for (int k = 0; k < clipFrames; ++k)
        writer.write(cv::Mat(clipHeight, clipWidth, CV_8UC3, cv::Scalar::all(20.0 * k)));
    return clip;
}

/// `count` 16-bit depth images of `size`; image k holds 100 (k + 1) units (mm by default).
void writeDepthFolder(const fs::path& dir, int count, cv::Size size, const std::string& prefix = "d")
{
    fs::create_directories(dir);
    for (int k = 0; k < count; ++k)
        ASSERT_TRUE(cv::imwrite((dir / fmt::format("{}{}.png", prefix, k)).string(),
                                cv::Mat(size, CV_16UC1, cv::Scalar(100.0 * (k + 1)))));
}

std::vector<Frame> readAll(FrameSource& source)
{
    std::vector<Frame> frames;
    while (std::optional<Frame> frame = source.next())
        frames.push_back(std::move(*frame));
    return frames;
}

SourceOptions optionsFor(fs::path input, std::optional<fs::path> depth = std::nullopt)
{
    SourceOptions options;
    options.input = std::move(input);
    options.depth = std::move(depth);
    return options;
}

/// What the library and the program log while `open` runs.
std::string logOf(const std::function<void()>& open)
{
    const test::LogCapture log;
    open();
    return log.text();
}

// Defect: a video with a depth folder or depth.txt announced as "no depth given; its frames pass
// through in focus" while every frame is blurred with that depth; a video alone must still say it.
TEST(PairedSource, OnlyAVideoWithoutDepthSaysItPassesThroughInFocus)
{
    const fs::path dir = test::scratchDir("streams_depth_message");
    const fs::path clip = writeClip(dir);
    writeDepthFolder(dir / "depth", clipFrames, {clipWidth, clipHeight});
    std::ofstream(dir / "depth.txt") << "0.0 depth/d0.png\n";
    for (const fs::path& depth : {dir / "depth", dir / "depth.txt"}) {
        const std::string log = logOf([&] { openSource(optionsFor(clip, depth)); });
        EXPECT_EQ(log.find("no depth"), std::string::npos) << depth << ": " << log;
    }
    const std::string alone = logOf([&] { openSource(optionsFor(clip)); });
    EXPECT_NE(alone.find("no depth given; its frames pass through in focus"), std::string::npos) << alone;
}

TEST(VideoFileSource, ReadsAClipItWrote)
{
    const fs::path dir = test::scratchDir("streams_clip");
    const fs::path clip = writeClip(dir);
    const std::unique_ptr<FrameSource> source = openSource(optionsFor(clip));
    EXPECT_FALSE(source->isLive());
    ASSERT_TRUE(source->frameCount().has_value());
    EXPECT_EQ(*source->frameCount(), std::size_t{clipFrames});
    EXPECT_DOUBLE_EQ(source->frameRate(), clipFps);
    const std::vector<Frame> frames = readAll(*source);
    ASSERT_EQ(frames.size(), std::size_t{clipFrames});
    for (std::size_t k = 0; k < frames.size(); ++k) {
        SCOPED_TRACE(k);
        EXPECT_EQ(frames[k].index, k);
        EXPECT_EQ(frames[k].color.size(), cv::Size(clipWidth, clipHeight));
        EXPECT_EQ(frames[k].color.type(), CV_8UC3);
        EXPECT_NEAR(cv::mean(frames[k].color)[1], 20.0 * double(k), 3.0) << "MJPEG of a flat grey";
        EXPECT_TRUE(frames[k].depth.empty());
        EXPECT_NEAR(frames[k].timestampS, double(k) / clipFps, 1e-3);
    }
}

TEST(PairedSource, VideoWithDepthFolderPairsByIndex)
{
    const fs::path dir = test::scratchDir("streams_video_depth_folder");
    const fs::path clip = writeClip(dir);
    // Half-size depth (the pipeline resizes it; same aspect ratio), named so that natural order
    // ("d2" < "d10") differs from plain string order.
    writeDepthFolder(dir / "depth", clipFrames, {clipWidth / 2, clipHeight / 2});
    const std::unique_ptr<FrameSource> source = openSource(optionsFor(clip, dir / "depth"));
    EXPECT_NE(source->describe().find("paired by index"), std::string::npos) << source->describe();
    EXPECT_EQ(source->frameCount(), std::optional<std::size_t>(clipFrames));
    const std::vector<Frame> frames = readAll(*source);
    ASSERT_EQ(frames.size(), std::size_t{clipFrames});
    for (std::size_t k = 0; k < frames.size(); ++k) {
        SCOPED_TRACE(k);
        ASSERT_EQ(frames[k].depth.size(), cv::Size(clipWidth / 2, clipHeight / 2)) << "native size kept";
        ASSERT_EQ(frames[k].depth.type(), CV_32FC1);
        EXPECT_FLOAT_EQ(frames[k].depth.at<float>(3, 5), 0.1f * float(k + 1));
        EXPECT_NEAR(cv::mean(frames[k].color)[0], 20.0 * double(k), 3.0);
    }
}

TEST(PairedSource, ShortDepthSequencePassesTheRestInFocus)
{
    const fs::path dir = test::scratchDir("streams_short_depth");
    const fs::path clip = writeClip(dir);
    writeDepthFolder(dir / "depth", 8, {clipWidth, clipHeight});
    auto source = std::make_unique<PairedSource>(openSource(optionsFor(clip)),
                                                 DepthSequence::fromFolder(dir / "depth", 1000.0, {}));
    const std::vector<Frame> frames = readAll(*source);
    ASSERT_EQ(frames.size(), std::size_t{clipFrames});
    for (std::size_t k = 0; k < frames.size(); ++k)
        EXPECT_EQ(frames[k].depth.empty(), k >= 8) << k;
    EXPECT_EQ(source->unpairedFrames(), 4u);
}

TEST(PairedSource, DepthListWithVideoUsesTumScale)
{
    const fs::path dir = test::scratchDir("streams_video_depth_list");
    const fs::path clip = writeClip(dir);
    writeDepthFolder(dir / "depth", clipFrames, {clipWidth, clipHeight});
    std::ofstream list(dir / "depth.txt");
    list << "# depth maps\n# timestamp filename\n";
    for (int k = 0; k < clipFrames; ++k)
        list << fmt::format("{:.6f} depth/d{}.png\n", 100.0 + 0.1 * k, k);
    list.close();
    const std::vector<Frame> frames = readAll(*openSource(optionsFor(clip, dir / "depth.txt")));
    ASSERT_EQ(frames.size(), std::size_t{clipFrames});
    // 16-bit depth from a TUM list is in 1/5000 m unless --depth-scale says otherwise.
    EXPECT_FLOAT_EQ(frames[3].depth.at<float>(0, 0), 400.0f / 5000.0f);
}

/// Colour frames with given timestamps and no depth, as a camera or a clip would give them.
class TimedColorSource final : public FrameSource {
public:
    explicit TimedColorSource(std::vector<double> times) : times_(std::move(times)) {}
    std::optional<Frame> next() override
    {
        if (next_ >= times_.size())
            return std::nullopt;
        Frame frame;
        frame.color = cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(100));
        frame.timestampS = times_[next_];
        frame.index = next_;
        frame.name = fmt::format("colour#{}", next_++);
        return frame;
    }
    std::optional<std::size_t> frameCount() const override { return times_.size(); }
    std::string describe() const override { return "timed colour"; }

private:
    std::vector<double> times_;
    std::size_t next_ = 0;
};

TEST(PairedSource, DepthFolderPairsByTimestamp)
{
    const fs::path dir = test::scratchDir("streams_depth_by_time");
    // Depth at 1, 1.03125, 1.0625, 1.09375 s (multiples of 1/32 s, exact in binary, so ties are
    // exact); the file names are the times; image k holds 100 (k+1) mm.
    fs::create_directories(dir / "depth");
    const std::vector<double> depthTimes = {1.0, 1.03125, 1.0625, 1.09375};
    for (std::size_t k = 0; k < depthTimes.size(); ++k)
        ASSERT_TRUE(cv::imwrite((dir / "depth" / fmt::format("{:.6f}.png", depthTimes[k])).string(),
                                cv::Mat(48, 64, CV_16UC1, cv::Scalar(100.0 * double(k + 1)))));
    DepthPairing pairing;
    pairing.mode = DepthPairing::Mode::Timestamp;
    pairing.maxGap = 0.020;
    pairing.alignStarts = false;
    // 1.001 -> 1 (1 ms); 1.05 -> 1.0625 (12.5 ms, nearer than 1.03125 at 18.75 ms);
    // 1.046875 lies 15.625 ms from 1.03125 and from 1.0625: the earlier wins; 1.2 and 0.975 have
    // nothing within 20 ms.
    const std::vector<double> colorTimes = {1.001, 1.05, 1.046875, 1.2, 0.975};
    const std::vector<std::optional<float>> want = {0.1f, 0.3f, 0.2f, std::nullopt, std::nullopt};
    PairedSource source(std::make_unique<TimedColorSource>(colorTimes),
                        DepthSequence::fromFolder(dir / "depth", 1000.0, pairing));
    const std::vector<Frame> frames = readAll(source);
    ASSERT_EQ(frames.size(), colorTimes.size());
    for (std::size_t k = 0; k < frames.size(); ++k) {
        SCOPED_TRACE(fmt::format("colour at {} s", colorTimes[k]));
        if (!want[k]) {
            EXPECT_TRUE(frames[k].depth.empty());
            continue;
        }
        ASSERT_FALSE(frames[k].depth.empty());
        EXPECT_FLOAT_EQ(depthMetres(frames[k]).at<float>(0, 0), *want[k]);
    }
    EXPECT_EQ(source.unpairedFrames(), 2u);

    // A folder whose names are not times cannot pair by timestamp.
    writeDepthFolder(dir / "named", 2, {64, 48});
    EXPECT_THROW(DepthSequence::fromFolder(dir / "named", 1000.0, pairing), SourceError);
}

TEST(PairedSource, AlignedStartsPairAClipWithAbsoluteDepthTimes)
{
    // A clip's times start at 0; TUM depth times are seconds since 1970. With alignStarts both
    // are measured from their first entry.
    const fs::path dir = test::scratchDir("streams_aligned");
    fs::create_directories(dir / "depth");
    for (int k = 0; k < 3; ++k)
        ASSERT_TRUE(cv::imwrite((dir / "depth" / fmt::format("{:.6f}.png", 1305031250.0 + 0.1 * k)).string(),
                                cv::Mat(48, 64, CV_16UC1, cv::Scalar(100.0 * (k + 1)))));
    DepthPairing pairing;
    pairing.mode = DepthPairing::Mode::Timestamp;
    PairedSource source(std::make_unique<TimedColorSource>(std::vector<double>{0.0, 0.105, 0.19}),
                        DepthSequence::fromFolder(dir / "depth", 1000.0, pairing));
    const std::vector<Frame> frames = readAll(source);
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_FLOAT_EQ(depthMetres(frames[0]).at<float>(0, 0), 0.1f);
    EXPECT_FLOAT_EQ(depthMetres(frames[1]).at<float>(0, 0), 0.2f);
    EXPECT_FLOAT_EQ(depthMetres(frames[2]).at<float>(0, 0), 0.3f);
}

TEST(PairedSource, TumDepthListByTimestampMatchesTheBenchmarkAssociations)
{
    // The bundled TUM clip: pairing rgb.txt times with depth.txt by nearest timestamp within
    // 20 ms must give the pairs of the benchmark's own associations.txt.
    const fs::path tum = test::dataDir() / "tum_fr1_rpy";
    std::vector<double> rgbTimes;
    std::vector<std::string> wantDepth;
    std::ifstream in(tum / "associations.txt");
    double rgbTime = 0.0, depthTime = 0.0;
    std::string rgbFile, depthFile;
    while (in >> rgbTime >> rgbFile >> depthTime >> depthFile) {
        rgbTimes.push_back(rgbTime);
        wantDepth.push_back((tum / depthFile).string());
    }
    ASSERT_EQ(rgbTimes.size(), 10u);
    DepthPairing pairing;
    pairing.mode = DepthPairing::Mode::Timestamp;
    pairing.alignStarts = false;
    const std::unique_ptr<DepthSequence> depth =
        DepthSequence::fromList(tum / "depth.txt", 5000.0, pairing);
    for (std::size_t k = 0; k < rgbTimes.size(); ++k) {
        Frame colour;
        colour.timestampS = rgbTimes[k];
        colour.index = k;
        const std::optional<DepthSample> sample = depth->depthFor(colour);
        ASSERT_TRUE(sample.has_value()) << k;
        EXPECT_EQ(sample->name, wantDepth[k]);
        EXPECT_EQ(sample->depth.image.size(), cv::Size(640, 480));
    }
}

TEST(PairedSource, DepthOfAnotherAspectRatioIsRefused)
{
    const fs::path dir = test::scratchDir("streams_aspect");
    writeDepthFolder(dir / "depth", 1, {48, 48}); // 1:1 depth for 4:3 colour
    PairedSource source(std::make_unique<TimedColorSource>(std::vector<double>{0.0}),
                        DepthSequence::fromFolder(dir / "depth", 1000.0, {}));
    EXPECT_THROW(source.next(), SourceError);
}

// ---- camera paths that are no cameras ----

std::string errorOf(const std::function<void()>& open)
{
    try {
        open();
    } catch (const SourceError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no SourceError";
    return {};
}

TEST(V4l2Source, ClearErrorsWithoutACamera)
{
    EXPECT_TRUE(isCameraPath("/dev/video0"));
    EXPECT_TRUE(isCameraPath("/dev/video42")); // whether or not it exists
    EXPECT_FALSE(isCameraPath("clip.mp4"));

    V4l2Options missing;
    missing.device = "/dev/video99";
    EXPECT_NE(errorOf([&] { V4l2Source{missing}; }).find("camera /dev/video99 does not exist"),
              std::string::npos);

    V4l2Options notV4l2;
    notV4l2.device = "/dev/null"; // a character device that answers no V4L2 ioctl
    EXPECT_NE(errorOf([&] { V4l2Source{notV4l2}; }).find("/dev/null is not a V4L2 device"),
              std::string::npos);

    const fs::path dir = test::scratchDir("streams_not_a_device");
    std::ofstream(dir / "video0") << "x";
    V4l2Options file;
    file.device = dir / "video0";
    EXPECT_NE(errorOf([&] { V4l2Source{file}; }).find("is not a device node"), std::string::npos);

    V4l2Options badRate;
    badRate.device = "/dev/video0";
    badRate.fps = 0.0;
    EXPECT_NE(errorOf([&] { V4l2Source{badRate}; }).find("frame rate must be positive"),
              std::string::npos);
}

TEST(V4l2Source, DepthCameraNeedsAColourCamera)
{
    const fs::path dir = test::scratchDir("streams_depth_camera");
    const fs::path clip = writeClip(dir);
    // /dev/null stands for a device node here: it exists on every machine.
    const std::string message = errorOf([&] { openSource(optionsFor(clip, "/dev/null")); });
    EXPECT_NE(message.find("pairs with a colour camera only"), std::string::npos) << message;
    const std::string notCamera = errorOf([&] { openSource(optionsFor("/dev/null")); });
    EXPECT_NE(notCamera.find("is not a V4L2 device"), std::string::npos) << notCamera;
}

} // namespace
} // namespace defocus
