// SPDX-License-Identifier: LGPL-2.1-or-later
// V4l2Source against real kernel drivers, run inside the VM of scripts/v4l2-vm-test.sh: vivid
// for the colour formats, v4l2loopback (fed by a producer thread in this process) for Z16 depth
// and MJPEG, two nodes paired by timestamp, and a camera unplugged mid-stream (vivid's
// "Disconnect" control). Devices: $DEFOCUS_VIVID (/dev/video0), $DEFOCUS_LOOPBACK (/dev/video1,
// /dev/video2 and /dev/video3 follow it); $DEFOCUS_EXPECT_LOOPBACK=1 makes a missing loopback
// device a failure instead of a skip.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sources/FrameSource.hpp"
#include "sources/PairedSource.hpp"
#include "sources/V4l2Formats.hpp"
#include "sources/V4l2Source.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

std::string env(const char* name, const char* fallback)
{
    const char* value = std::getenv(name);
    return value && *value ? value : fallback;
}

fs::path vividDevice()
{
    return env("DEFOCUS_VIVID", "/dev/video0");
}

/// The n-th loopback node (0: Z16, 1: MJPG, 2: Z16 for pairing).
fs::path loopbackDevice(int n)
{
    const std::string first = env("DEFOCUS_LOOPBACK", "/dev/video1");
    const int number = std::atoi(first.substr(first.find_first_of("0123456789")).c_str());
    return fmt::format("/dev/video{}", number + n);
}

bool loopbackExpected()
{
    return env("DEFOCUS_EXPECT_LOOPBACK", "0") == "1";
}

#define REQUIRE_DEVICE(path)                                                                       \
    do {                                                                                           \
        if (!fs::exists(path)) {                                                                   \
            if (loopbackExpected() || (path) == vividDevice())                                     \
                FAIL() << (path) << " does not exist";                                             \
            GTEST_SKIP() << (path) << " does not exist";                                           \
        }                                                                                          \
    } while (0)

/// Sets the control whose name is `name` (e.g. vivid's "OSD Text Mode"); false when the device
/// has none by that name.
bool setControl(int fd, const std::string& name, int value)
{
    v4l2_queryctrl query{};
    query.id = V4L2_CTRL_FLAG_NEXT_CTRL;
    while (ioctl(fd, VIDIOC_QUERYCTRL, &query) == 0) {
        if (name == reinterpret_cast<const char*>(query.name)) {
            v4l2_control control{};
            control.id = query.id;
            control.value = value;
            return ioctl(fd, VIDIOC_S_CTRL, &control) == 0;
        }
        query.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
    }
    return false;
}

/// Writes frames into a v4l2loopback node as a camera would: frame 0 at once (so that the node
/// offers the format to readers), then frame k every 1/fps seconds from a thread.
class LoopbackProducer {
public:
    LoopbackProducer(const fs::path& device, std::uint32_t fourcc, int width, int height, double fps,
                     std::function<Bytes(int)> frame)
        : frame_(std::move(frame))
    {
        fd_ = ::open(device.c_str(), O_RDWR | O_CLOEXEC);
        if (fd_ < 0)
            throw std::runtime_error(fmt::format("open {}: {}", device.string(), std::strerror(errno)));
        v4l2_format format{};
        format.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        format.fmt.pix.width = static_cast<__u32>(width);
        format.fmt.pix.height = static_cast<__u32>(height);
        format.fmt.pix.pixelformat = fourcc;
        format.fmt.pix.field = V4L2_FIELD_NONE;
        if (fourcc == V4L2_PIX_FMT_Z16)
            format.fmt.pix.bytesperline = static_cast<__u32>(width * 2);
        if (ioctl(fd_, VIDIOC_S_FMT, &format) != 0)
            throw std::runtime_error(fmt::format("S_FMT output {} on {}: {}", v4l2::fourccName(fourcc),
                                                 device.string(), std::strerror(errno)));
        if (format.fmt.pix.pixelformat != fourcc)
            throw std::runtime_error(fmt::format("{} took {} instead of {} (Z16 patch missing?)",
                                                 device.string(),
                                                 v4l2::fourccName(format.fmt.pix.pixelformat),
                                                 v4l2::fourccName(fourcc)));
        write(0);
        thread_ = std::thread([this, fps] {
            const auto period = std::chrono::duration<double>(1.0 / fps);
            auto due = std::chrono::steady_clock::now();
            for (int k = 1; !stop_; ++k) {
                due += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
                std::this_thread::sleep_until(due);
                write(k);
            }
        });
    }
    ~LoopbackProducer()
    {
        stop_ = true;
        if (thread_.joinable())
            thread_.join();
        ::close(fd_);
    }
    LoopbackProducer(const LoopbackProducer&) = delete;
    LoopbackProducer& operator=(const LoopbackProducer&) = delete;

private:
    void write(int k)
    {
        const Bytes bytes = frame_(k);
        if (::write(fd_, bytes.data(), bytes.size()) != static_cast<ssize_t>(bytes.size()))
            ADD_FAILURE() << "producer: short write of frame " << k << ": " << std::strerror(errno);
    }

    int fd_ = -1;
    std::function<Bytes(int)> frame_;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

/// Z16 test frame k: value(x, y) = 500 + 37k + 3x + 5y units, so k is read back from (0, 0).
std::uint16_t z16Value(int k, int x, int y)
{
    return static_cast<std::uint16_t>(500 + 37 * k + 3 * x + 5 * y);
}

Bytes z16Frame(int k, int width, int height)
{
    Bytes bytes;
    bytes.reserve(static_cast<std::size_t>(width * height * 2));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::uint16_t v = z16Value(k, x, y);
            bytes.push_back(static_cast<std::uint8_t>(v & 0xFF));
            bytes.push_back(static_cast<std::uint8_t>(v >> 8));
        }
    return bytes;
}

/// The producer frame number of a captured Z16 frame, or -1 when its values are not exactly
/// those of one produced frame.
int z16FrameNumber(const cv::Mat& metres, double unitsPerMetre)
{
    const auto units = [&](int x, int y) {
        return static_cast<int>(std::lround(metres.at<float>(y, x) * unitsPerMetre));
    };
    const int k = (units(0, 0) - 500) / 37;
    for (int y = 0; y < metres.rows; ++y)
        for (int x = 0; x < metres.cols; ++x)
            if (units(x, y) != z16Value(k, x, y))
                return -1;
    return k;
}

double meanAbsDiff(const cv::Mat& a, const cv::Mat& b)
{
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    const cv::Scalar m = cv::mean(diff);
    return (m[0] + m[1] + m[2]) / 3.0;
}

std::vector<Frame> capture(V4l2Source& source, int count)
{
    std::vector<Frame> frames;
    for (int i = 0; i < count; ++i)
        frames.push_back(*source.next());
    return frames;
}

void expectIncreasingTimes(const std::vector<Frame>& frames, double rate)
{
    for (std::size_t i = 1; i < frames.size(); ++i)
        EXPECT_GT(frames[i].timestampS, frames[i - 1].timestampS) << "frame " << i;
    // Single intervals vary under software emulation (a late frame is followed by a quick
    // one), but on average frames come at about the rate.
    const double mean = (frames.back().timestampS - frames.front().timestampS) / double(frames.size() - 1);
    EXPECT_GT(mean, 0.5 / rate);
    EXPECT_LT(mean, 3.0 / rate);
    std::printf("  mean frame interval %.1f ms (%.3g Hz asked)\n", mean * 1000.0, rate);
}

// ---- vivid: the colour formats ----

class VividFormats : public ::testing::Test {
protected:
    static void SetUpTestSuite()
    {
        // Frames without the changing OSD text are identical over time and across formats.
        const int fd = ::open(vividDevice().c_str(), O_RDWR);
        if (fd >= 0) {
            setControl(fd, "OSD Text Mode", 2);
            ::close(fd);
        }
    }
    static cv::Mat& rgbReference()
    {
        static cv::Mat reference;
        return reference;
    }
};

struct FormatCase {
    const char* fourcc;
    double maxMeanDiff; ///< against the RGB3 frame, grey levels; see the comment at its use
    bool yuvColor = false; ///< V4l2Options::yuvColor: Y'CbCr kept as it was captured
};

void checkVividFormat(const FormatCase& format, cv::Mat& reference)
{
    SCOPED_TRACE(std::string(format.fourcc) + (format.yuvColor ? " as captured" : ""));
    V4l2Options options;
    options.yuvColor = format.yuvColor;
    options.device = vividDevice();
    options.width = 320;
    options.height = 240;
    options.fps = 30.0;
    options.pixelFormat = format.fourcc;
    V4l2Source source(options);
    EXPECT_EQ(v4l2::fourccName(source.pixelFormat()), v4l2::fourccName(v4l2::fourccFromName(format.fourcc)));
    EXPECT_EQ(source.size().width, 320);
    EXPECT_TRUE(source.isLive());
    const auto start = std::chrono::steady_clock::now();
    std::vector<Frame> frames = capture(source, 6);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (Frame& frame : frames) {
        if (format.yuvColor) {
            // The planes as captured, made BGR by OpenCV (the filter's yuvToBgr() is held to
            // within a level of it by LibraryYuv) and compared below.
            ASSERT_TRUE(frame.color.empty());
            ASSERT_EQ(frame.yuv.y.size(), source.size());
            EXPECT_EQ(frame.yuv.layout, std::string(format.fourcc) == "NV12" ? YuvImage::Layout::Nv12 : YuvImage::Layout::Yuyv);
            if (frame.yuv.layout == YuvImage::Layout::Nv12)
                cv::cvtColorTwoPlane(frame.yuv.y, frame.yuv.u, frame.color, cv::COLOR_YUV2BGR_NV12);
            else
                cv::cvtColor(frame.yuv.y, frame.color, cv::COLOR_YUV2BGR_YUYV);
        }
        ASSERT_EQ(frame.color.size(), source.size());
        ASSERT_EQ(frame.color.type(), CV_8UC3);
        EXPECT_TRUE(frame.depth.empty());
        cv::Scalar mean, stddev;
        cv::meanStdDev(frame.color, mean, stddev);
        EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 30.0) << "colour bars are far from constant";
    }
    expectIncreasingTimes(frames, source.frameRate());
    const cv::Mat& last = frames.back().color;
    if (std::string(format.fourcc) == "GREY") {
        std::vector<cv::Mat> channels;
        cv::split(last, channels);
        EXPECT_EQ(cv::norm(channels[0], channels[1], cv::NORM_INF), 0.0);
        EXPECT_EQ(cv::norm(channels[0], channels[2], cv::NORM_INF), 0.0);
    } else if (std::string(format.fourcc) == "RGB3") {
        reference = last.clone();
    } else if (!reference.empty()) {
        const double diff = meanAbsDiff(last, reference);
        std::printf("  %s vs RGB3: mean |difference| %.2f grey levels\n", format.fourcc, diff);
        EXPECT_LE(diff, format.maxMeanDiff);
    }
    std::printf("  %s: %dx%d at %.3g Hz (driver), 6 frames in %.2f s, %zu dropped\n", format.fourcc,
                source.size().width, source.size().height, source.frameRate(), seconds,
                source.droppedFrames());
}

TEST_F(VividFormats, CapturesEachColourFormat)
{
    REQUIRE_DEVICE(vividDevice());
    // RGB3 first: it is the reference the others are compared with. BGR3 holds the same bytes
    // in another order (0 difference); YUYV (4:2:2) and NV12 (4:2:0) share chroma between 2 and
    // 4 pixels and round through 8-bit Y'CbCr, which costs about 1 grey level on average plus
    // the bar edges, so allow 4.
    // The same holds for YUYV and NV12 kept as they were captured (SourceSettings::yuvColor),
    // once made BGR.
    const FormatCase formats[] = {{"RGB3", 0.0},       {"BGR3", 0.0},       {"YUYV", 4.0}, {"NV12", 4.0},
                                  {"YUYV", 4.0, true}, {"NV12", 4.0, true}, {"GREY", 0.0}};
    for (const FormatCase& format : formats)
        checkVividFormat(format, rgbReference());
}

TEST_F(VividFormats, ChoosesAFormatByItself)
{
    REQUIRE_DEVICE(vividDevice());
    V4l2Options options;
    options.device = vividDevice();
    options.width = 320;
    options.height = 240;
    V4l2Source source(options);
    EXPECT_TRUE(v4l2::isColorFormat(source.pixelFormat())) << v4l2::fourccName(source.pixelFormat());
    EXPECT_EQ(capture(source, 2).back().color.size(), source.size());
}

TEST_F(VividFormats, MjpegAskedOfVividGivesYuyvAndIsRead)
{
    // vivid has no MJPEG and answers S_FMT with YUYV without an error.
    REQUIRE_DEVICE(vividDevice());
    V4l2Options options;
    options.device = vividDevice();
    options.width = 320;
    options.height = 240;
    options.pixelFormat = "MJPG";
    V4l2Source source(options);
    EXPECT_EQ(source.pixelFormat(), V4L2_PIX_FMT_YUYV);
    EXPECT_EQ(capture(source, 2).back().color.size(), source.size());
}

TEST_F(VividFormats, DepthAskedOfVividIsRefused)
{
    REQUIRE_DEVICE(vividDevice());
    V4l2Options options;
    options.device = vividDevice();
    options.role = V4l2Options::Role::Depth;
    try {
        V4l2Source source(options);
        FAIL() << "a colour camera was accepted as a depth camera";
    } catch (const SourceError& e) {
        const std::string message = e.what();
        std::printf("  %s\n", e.what());
        EXPECT_NE(message.find("is not a depth camera"), std::string::npos) << message;
        EXPECT_NE(message.find("YUYV"), std::string::npos) << message;
    }
}

// ---- v4l2loopback: Z16 and MJPEG from a producer ----

TEST(Loopback, Z16RoundTrips)
{
    const fs::path device = loopbackDevice(0);
    REQUIRE_DEVICE(device);
    constexpr int w = 320, h = 240;
    LoopbackProducer producer(device, V4L2_PIX_FMT_Z16, w, h, 30.0,
                              [](int k) { return z16Frame(k, w, h); });
    V4l2Options options;
    options.device = device;
    options.role = V4l2Options::Role::Depth;
    options.width = w;
    options.height = h;
    V4l2Source source(options);
    EXPECT_EQ(source.pixelFormat(), V4L2_PIX_FMT_Z16);
    const std::vector<Frame> frames = capture(source, 6);
    int previous = -1;
    for (const Frame& frame : frames) {
        ASSERT_TRUE(frame.color.empty());
        ASSERT_EQ(frame.depth.size(), cv::Size(w, h));
        ASSERT_EQ(frame.depth.type(), CV_16UC1) << "Z16 as the camera gave it";
        EXPECT_EQ(frame.depthScale, 1000.0);
        const int k = z16FrameNumber(depthMetres(frame), 1000.0);
        EXPECT_GE(k, 0) << "captured depth is not exactly a produced frame";
        EXPECT_GT(k, previous) << "frames in order, none repeated";
        previous = k;
    }
    expectIncreasingTimes(frames, 30.0);
    std::printf("  Z16 %dx%d: producer frames up to %d read, %zu dropped\n", w, h, previous,
                source.droppedFrames());
}

TEST(Loopback, MjpegRoundTrips)
{
    const fs::path device = loopbackDevice(1);
    REQUIRE_DEVICE(device);
    constexpr int w = 320, h = 240;
    cv::Mat image(h, w, CV_8UC3);
    for (int i = 0; i < 8; ++i) // eight vertical bars of distinct colours
        image(cv::Rect(i * w / 8, 0, w / 8, h))
            .setTo(cv::Scalar((i & 1) * 255, ((i >> 1) & 1) * 255, ((i >> 2) & 1) * 255));
    Bytes jpeg;
    ASSERT_TRUE(cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95}));
    const cv::Mat reference = cv::imdecode(jpeg, cv::IMREAD_COLOR);
    LoopbackProducer producer(device, V4L2_PIX_FMT_MJPEG, w, h, 30.0, [&](int) { return jpeg; });

    V4l2Options options;
    options.device = device;
    options.width = w;
    options.height = h;
    V4l2Source source(options); // MJPG is all the node lists, so it is chosen
    EXPECT_EQ(source.pixelFormat(), V4L2_PIX_FMT_MJPEG);
    const std::vector<Frame> frames = capture(source, 5);
    for (const Frame& frame : frames) {
        ASSERT_EQ(frame.color.size(), cv::Size(w, h));
        EXPECT_EQ(cv::norm(frame.color, reference, cv::NORM_INF), 0.0) << "bytes changed on the way";
        // JPEG at quality 95 of flat bars: ringing at the 7 bar edges only.
        EXPECT_LT(meanAbsDiff(frame.color, image), 3.0);
    }
    expectIncreasingTimes(frames, 30.0);
}

TEST(Loopback, ColourAndDepthNodesPairByTimestamp)
{
    // RealSense-style: colour from vivid, Z16 from a loopback node, opened the way the command
    // line opens them: defocus /dev/video0 --depth /dev/video3.
    const fs::path depthDevice = loopbackDevice(2);
    REQUIRE_DEVICE(vividDevice());
    REQUIRE_DEVICE(depthDevice);
    // vivid's webcam gives 320x180 for 320x240; the depth matches that aspect ratio.
    constexpr int w = 320, h = 180;
    LoopbackProducer producer(depthDevice, V4L2_PIX_FMT_Z16, w, h, 30.0,
                              [](int k) { return z16Frame(k, w, h); });
    SourceOptions options;
    options.input = vividDevice();
    options.depth = depthDevice;
    options.width = 320;
    options.height = 240;
    options.fps = 30.0;
    const std::unique_ptr<FrameSource> source = openSource(options);
    EXPECT_TRUE(source->isLive());
    std::printf("  %s\n", source->describe().c_str());
    int paired = 0;
    constexpr int frames = 12;
    for (int i = 0; i < frames; ++i) {
        const std::optional<Frame> frame = source->next();
        ASSERT_TRUE(frame.has_value());
        ASSERT_FALSE(frame->color.empty());
        if (frame->depth.empty())
            continue;
        ++paired;
        EXPECT_EQ(frame->depth.size(), cv::Size(w, h));
        EXPECT_GE(z16FrameNumber(frame->depth, 1000.0), 0);
    }
    std::printf("  %d of %d colour frames paired with depth\n", paired, frames);
    // Two free-running 30 Hz streams are at most half a frame (16.7 ms) apart, inside the 20 ms
    // tolerance; emulation jitter may still miss some.
    EXPECT_GE(paired, frames / 2);
}

// ---- unplugged mid-stream: runs last, vivid is gone afterwards ----

TEST(ZzDisconnect, UnpluggedCameraGivesAClearError)
{
    REQUIRE_DEVICE(vividDevice());
    V4l2Options options;
    options.device = vividDevice();
    options.width = 320;
    options.height = 240;
    V4l2Source source(options);
    const int control = ::open(vividDevice().c_str(), O_RDWR);
    ASSERT_GE(control, 0);
    capture(source, 3);
    // vivid's "Disconnect" button unregisters the node the way a USB unplug does.
    ASSERT_TRUE(setControl(control, "Disconnect", 1));
    ::close(control);
    try {
        source.next();
        FAIL() << "a frame after the camera was unplugged";
    } catch (const SourceError& e) {
        std::printf("  %s\n", e.what());
        const std::string want = fmt::format("camera {} disconnected after 3 frames", vividDevice().string());
        EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace defocus
