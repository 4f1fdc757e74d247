// SPDX-License-Identifier: LGPL-2.1-or-later
// The virtual camera's pixel conversion (BGR to BT.601 YUYV) against the textbook equations and
// through the capture side's decoder, and its errors for outputs that are not virtual cameras.
// Writing to a real v4l2loopback node is tested in the VM (scripts/v4l2-vm-test.sh, docs/v4l2.md).
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "sinks/FrameSink.hpp"
#include "sinks/V4l2OutputSink.hpp"
#include "sources/V4l2Formats.hpp"

namespace defocus {
namespace {

// BT.601 for 8-bit R'G'B' in [0, 255], written as Rec. ITU-R BT.601-7 section 2.5.3 gives it (the
// matrix with 219 and 224 folded in), not as the sink computes it.
double y601(double r, double g, double b) { return 16.0 + (65.481 * r + 128.553 * g + 24.966 * b) / 255.0; }
double cb601(double r, double g, double b) { return 128.0 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255.0; }
double cr601(double r, double g, double b) { return 128.0 + (112.0 * r - 93.786 * g - 18.214 * b) / 255.0; }

cv::Mat randomImage(int width, int height, unsigned seed)
{
    cv::Mat image(height, width, CV_8UC3);
    cv::RNG rng(seed);
    rng.fill(image, cv::RNG::UNIFORM, 0, 256);
    return image;
}

// Catches wrong coefficients, full range instead of limited, U and V or R and B swapped, a
// truncation instead of rounding, and chroma taken from one pixel of the pair instead of both.
TEST(Yuyv601, EveryByteIsTheExactValueRounded)
{
    cv::Mat image = randomImage(64, 16, 7);
    // The corners of the RGB cube on the first row: black, white, red, green, blue, ...
    const cv::Vec3b corners[] = {{0, 0, 0}, {255, 255, 255}, {0, 0, 255}, {0, 255, 0},
                                 {255, 0, 0}, {0, 255, 255}, {255, 0, 255}, {255, 255, 0}};
    for (int i = 0; i < 8; ++i)
        image.at<cv::Vec3b>(0, 2 * i) = image.at<cv::Vec3b>(0, 2 * i + 1) = corners[i];
    std::vector<std::uint8_t> yuyv;
    encodeYuyv601(image, yuyv);
    ASSERT_EQ(yuyv.size(), static_cast<std::size_t>(64 * 16 * 2));
    // Each byte is the exact value rounded: within half a code, plus 3e-4 for the equations'
    // coefficients, which the standard prints to 3 decimals (224 x 0.168736 = 37.796864, ...).
    constexpr double bound = 0.5 + 1e-3;
    double worst = 0.0;
    for (int y = 0; y < image.rows; ++y)
        for (int x = 0; x < image.cols; x += 2) {
            const cv::Vec3b p0 = image.at<cv::Vec3b>(y, x), p1 = image.at<cv::Vec3b>(y, x + 1);
            const std::uint8_t* q = &yuyv[static_cast<std::size_t>((y * image.cols + x) * 2)];
            const double r = 0.5 * (p0[2] + p1[2]), g = 0.5 * (p0[1] + p1[1]), b = 0.5 * (p0[0] + p1[0]);
            const double errors[] = {q[0] - y601(p0[2], p0[1], p0[0]), q[2] - y601(p1[2], p1[1], p1[0]),
                                     q[1] - cb601(r, g, b), q[3] - cr601(r, g, b)};
            for (const double e : errors) {
                worst = std::max(worst, std::abs(e));
                ASSERT_LE(std::abs(e), bound) << "pixel pair at " << x << "," << y;
            }
        }
    // The ends of the ranges: black 16, white 235, chroma 16..240 with 128 for grey.
    EXPECT_EQ((std::vector<int>{yuyv[0], yuyv[1], yuyv[2], yuyv[3]}), (std::vector<int>{16, 128, 16, 128}));
    EXPECT_EQ((std::vector<int>{yuyv[4], yuyv[5], yuyv[6], yuyv[7]}), (std::vector<int>{235, 128, 235, 128}));
    EXPECT_EQ(yuyv[8 + 3], 240);  // red: Cr at its top
    EXPECT_EQ(yuyv[16 + 1], 240); // blue: Cb at its top
    EXPECT_GT(worst, 0.25);       // the random pixels did exercise the rounding
}

// The capture side (V4l2Source, OpenCV's BT.601 decoder) reads the bytes back as the colour written.
// Pairs of equal pixels, so 4:2:2 loses nothing; what remains is rounding: Y to half a code is
// 255/219 x 0.5 = 0.58 levels, Cb to half a code moves B by 2.018 x 0.5 = 1.01 levels (R by
// 1.596 x 0.5, G by (0.391 + 0.813) x 0.5: less), the decoder's own rounding 0.5: 2.09 in all,
// so at most 2 levels apart. Catches an encoder whose range or matrix the decoder does not share.
TEST(Yuyv601, CaptureSideDecodesItBackWithinRounding)
{
    cv::Mat image = randomImage(32, 24, 11);
    for (int y = 0; y < image.rows; ++y)
        for (int x = 0; x < image.cols; x += 2)
            image.at<cv::Vec3b>(y, x + 1) = image.at<cv::Vec3b>(y, x);
    std::vector<std::uint8_t> yuyv;
    encodeYuyv601(image, yuyv);
    const cv::Mat back = v4l2::convertYuyv(std::span<const std::uint8_t>(yuyv), image.cols, image.rows, 0);
    ASSERT_EQ(back.type(), CV_8UC3);
    EXPECT_LE(cv::norm(back, image, cv::NORM_INF), 2.0);
}

// Catches a device path sent to the image sinks (an "unknown extension" error) and a camera or
// other file taken for a virtual camera.
TEST(V4l2OutputSink, OnlyDeviceNodesAreVirtualCamerasAndOthersAreRefusedClearly)
{
    EXPECT_TRUE(isV4l2DevicePath("/dev/video10"));
    EXPECT_TRUE(isV4l2DevicePath("/dev/v4l/by-id/usb-defocus-video-index0"));
    EXPECT_FALSE(isV4l2DevicePath("out/video.mp4"));
    EXPECT_FALSE(isV4l2DevicePath("/tmp/dev/video0.png"));

    try {
        openSink({"/dev/video987", 30.0, false});
        FAIL() << "a missing node opened";
    } catch (const SinkError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("/dev/video987 does not exist"), std::string::npos) << message;
        EXPECT_NE(message.find("v4l2loopback"), std::string::npos) << message;
    }
    try {
        V4l2OutputSink sink("/dev/null", 30.0);
        FAIL() << "/dev/null taken for a virtual camera";
    } catch (const SinkError& error) {
        EXPECT_NE(std::string(error.what()).find("/dev/null is not a V4L2 device"), std::string::npos)
            << error.what();
    }
}

} // namespace
} // namespace defocus
