// SPDX-License-Identifier: LGPL-2.1-or-later
// The accuracy metrics checked analytically: PSNR of identical images and of a known MSE, SSIM of
// identical images, the region masks partitioning the image, and the zones of the corpus report.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "bench/Metrics.hpp"
#include "bench/methods/Method.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

cv::Mat noise(int rows, int cols, unsigned seed)
{
    cv::Mat image(rows, cols, CV_32FC3);
    cv::RNG rng(seed);
    rng.fill(image, cv::RNG::UNIFORM, 0.0, 1.0);
    return image;
}

TEST(Metrics, PsnrOfIdenticalImagesIsInfinite)
{
    const cv::Mat image = noise(40, 50, 1);
    EXPECT_EQ(psnrLinear(image, image), std::numeric_limits<double>::infinity());
    EXPECT_EQ(psnrSrgb(image, image), std::numeric_limits<double>::infinity());
    EXPECT_EQ(psnrFromMse(0.0), std::numeric_limits<double>::infinity());
}

TEST(Metrics, PsnrOfAKnownMse)
{
    // Every value off by 0.1: MSE 0.01, PSNR 10 log10(1 / 0.01) = 20 dB.
    const cv::Mat a(30, 30, CV_32FC3, cv::Scalar::all(0.5)), b(30, 30, CV_32FC3, cv::Scalar::all(0.6));
    EXPECT_NEAR(psnrLinear(a, b), 20.0, 1e-5);
    EXPECT_NEAR(psnrFromMse(1e-4), 40.0, 1e-12);
    // Values are clipped to [0, 1] first: HDR 2.0 and 1.0 agree, NaN counts as 0.
    const cv::Mat hdr(30, 30, CV_32FC3, cv::Scalar::all(2.0)), one(30, 30, CV_32FC3, cv::Scalar::all(1.0));
    EXPECT_EQ(psnrLinear(hdr, one), std::numeric_limits<double>::infinity());
    cv::Mat withNan = a.clone();
    withNan.at<cv::Vec3f>(0, 0) = cv::Vec3f(std::nanf(""), 0.5f, 0.5f);
    const double mse = 0.25 / (30.0 * 30.0 * 3.0); // one value off by 0.5
    EXPECT_NEAR(psnrLinear(withNan, a), 10.0 * std::log10(1.0 / mse), 1e-4);
}

TEST(Metrics, PsnrOverAMaskCountsOnlyItsPixels)
{
    cv::Mat a(20, 20, CV_32FC3, cv::Scalar::all(0.5)), b = a.clone();
    b(cv::Rect(0, 0, 10, 20)).setTo(cv::Scalar::all(0.6)); // left half off by 0.1
    cv::Mat left = cv::Mat::zeros(20, 20, CV_8UC1), right = cv::Mat::zeros(20, 20, CV_8UC1);
    left(cv::Rect(0, 0, 10, 20)).setTo(255);
    right(cv::Rect(10, 0, 10, 20)).setTo(255);
    EXPECT_NEAR(psnrLinear(a, b, left), 20.0, 1e-5);
    EXPECT_EQ(psnrLinear(a, b, right), std::numeric_limits<double>::infinity());
    EXPECT_NEAR(psnrLinear(a, b), 10.0 * std::log10(1.0 / 0.005), 1e-5);
    EXPECT_TRUE(std::isnan(psnrLinear(a, b, cv::Mat::zeros(20, 20, CV_8UC1))));
}

TEST(Metrics, SsimOfIdenticalImagesIsOne)
{
    const cv::Mat image = noise(64, 80, 2);
    EXPECT_NEAR(ssimLuma(image, image), 1.0, 1e-12);
    const cv::Mat other = noise(64, 80, 3);
    EXPECT_LT(ssimLuma(image, other), 0.5);
    // A flat image against itself: both variances 0, SSIM still 1 thanks to C1, C2.
    const cv::Mat flat(32, 32, CV_32FC3, cv::Scalar::all(0.3));
    EXPECT_NEAR(ssimLuma(flat, flat), 1.0, 1e-12);
}

TEST(Metrics, RegionMasksPartitionTheImage)
{
    // Left: in focus (CoC 0.2 px); right: a far background (CoC 10 px); a step between them at
    // x = 50; below row 40 a gentle ramp (0.1 px of CoC per column) that is no edge.
    const int rows = 60, cols = 100;
    cv::Mat coc(rows, cols, CV_32FC1);
    for (int y = 0; y < rows; ++y)
        for (int x = 0; x < cols; ++x)
            coc.at<float>(y, x) = y < 40 ? (x < 50 ? 0.2f : 10.0f) : 0.1f * static_cast<float>(x);
    const cv::Mat labels = regionMap(coc);
    ASSERT_EQ(labels.type(), CV_8UC1);

    int counts[3] = {0, 0, 0};
    for (int y = 0; y < rows; ++y)
        for (int x = 0; x < cols; ++x) {
            const int label = labels.at<uchar>(y, x);
            ASSERT_GE(label, 0);
            ASSERT_LE(label, 2);
            ++counts[label];
        }
    EXPECT_EQ(counts[0] + counts[1] + counts[2], rows * cols);

    // The band reaches max(|c|) / 2 + 1 = 6 px from the step on both sides (rows well above 40,
    // where the ramp's own edge with the step region does not interfere).
    const auto at = [&](int x, int y) { return static_cast<Region>(labels.at<uchar>(y, x)); };
    EXPECT_EQ(at(49, 10), Region::DepthEdge);
    EXPECT_EQ(at(50, 10), Region::DepthEdge);
    EXPECT_EQ(at(44, 10), Region::DepthEdge);
    EXPECT_EQ(at(55, 10), Region::DepthEdge);
    EXPECT_EQ(at(42, 10), Region::InFocus);
    EXPECT_EQ(at(58, 10), Region::OutOfFocus);
    // The ramp changes by 0.1 px per pixel: no edge inside it, in focus where |c| < 1.
    EXPECT_EQ(at(5, 55), Region::InFocus);
    EXPECT_EQ(at(30, 55), Region::OutOfFocus);

    // measureError's shares are the same partition.
    const cv::Mat image(rows, cols, CV_32FC3, cv::Scalar::all(0.5));
    const ErrorReport report = measureError(image, image, labels);
    EXPECT_NEAR(report.regionShare[0] + report.regionShare[1] + report.regionShare[2], 1.0, 1e-12);
    for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(report.regionShare[static_cast<std::size_t>(i)], counts[i] / double(rows * cols), 1e-12);
    EXPECT_EQ(report.psnrLinear, std::numeric_limits<double>::infinity());
}

TEST(Metrics, CocMapFollowsTheLensModel)
{
    LensSettings lens = blenderSpheresLens();
    lens.fieldOfView = FieldOfView::ImageDistance; // the documented figures use the lens formula
    const CocCoefficients k = cocCoefficients(lens, 640);
    cv::Mat depth(1, 3, CV_32FC1);
    depth.at<float>(0, 0) = 1.43f;
    depth.at<float>(0, 1) = 5.0f;
    depth.at<float>(0, 2) = 30.0f;
    const cv::Mat coc = cocMap(depth, k);
    // The Blender scene's documented CoCs at 640 px: 46.6 px at 1.43 m (near), 15.6 at 30 m.
    EXPECT_NEAR(coc.at<float>(0, 0), -46.6f, 0.1f);
    EXPECT_NEAR(coc.at<float>(0, 1), 0.0f, 1e-4f);
    EXPECT_NEAR(coc.at<float>(0, 2), 15.6f, 0.1f);
}

// Defect caught: a lights zone of the wrong reach (a radius or distance in the wrong unit, a
// threshold that takes white itself for a light) or lights losing to the other zones.
TEST(MetricsZones, LightsReachThirtyPixelsFromPixelsAboveWhite)
{
    cv::Mat input(120, 160, CV_32FC3, cv::Scalar::all(0.5));
    input.at<cv::Vec3f>(60, 80) = cv::Vec3f(0.2f, 1.5f, 0.2f); // one channel above white
    input.at<cv::Vec3f>(10, 10) = cv::Vec3f(1.0f, 1.0f, 1.0f); // white itself is no light
    const cv::Mat coc(input.size(), CV_32FC1, cv::Scalar(5.0f)); // all far, no depth edge
    const cv::Mat zones = zoneMap(input, coc);
    const auto at = [&](int y, int x) { return static_cast<Zone>(zones.at<uchar>(y, x)); };
    EXPECT_EQ(at(60, 80), Zone::Lights);
    EXPECT_EQ(at(60, 110), Zone::Lights);  // 30 px right
    EXPECT_EQ(at(60, 111), Zone::Far);     // 31 px
    EXPECT_EQ(at(81, 101), Zone::Lights);  // 29.7 px diagonally
    EXPECT_EQ(at(82, 102), Zone::Far);     // 31.1 px
    EXPECT_EQ(at(10, 10), Zone::Far);
}

// Defect caught: near and far swapped (the CoC's sign), in-focus or depth-edge pixels counted
// as near or far, or a pixel in two zones.
TEST(MetricsZones, NearFarInFocusAndEdgesFromTheCoc)
{
    const cv::Mat input(60, 90, CV_32FC3, cv::Scalar::all(0.3));
    cv::Mat coc(input.size(), CV_32FC1, cv::Scalar(0.0f));
    coc.colRange(0, 30).setTo(-6.0f); // near
    coc.colRange(60, 90).setTo(0.2f); // in focus, a smooth step from the middle's 0
    coc.colRange(30, 60).setTo(0.0f);
    coc.colRange(30, 60).rowRange(0, 30).setTo(0.5f);
    cv::Mat far = coc.clone();
    const cv::Mat zones = zoneMap(input, coc);
    EXPECT_EQ(static_cast<Zone>(zones.at<uchar>(30, 5)), Zone::Near);
    EXPECT_EQ(static_cast<Zone>(zones.at<uchar>(30, 30)), Zone::DepthEdge); // the -6 | 0 jump
    EXPECT_EQ(static_cast<Zone>(zones.at<uchar>(30, 80)), Zone::InFocus);
    far.setTo(8.0f);
    EXPECT_EQ(static_cast<Zone>(zoneMap(input, far).at<uchar>(30, 45)), Zone::Far);
    for (int y = 0; y < zones.rows; ++y)
        for (int x = 0; x < zones.cols; ++x)
            ASSERT_LE(zones.at<uchar>(y, x), static_cast<uchar>(Zone::Far));
}

// Defect caught: error shares that do not add up to the whole image's error (a zone's MSE
// weighted by the wrong pixel count), or PSNR computed over the wrong zone.
TEST(MetricsZones, ErrorSharesAddUpAndFollowTheError)
{
    cv::Mat input(80, 80, CV_32FC3, cv::Scalar::all(0.4));
    input.at<cv::Vec3f>(10, 10) = cv::Vec3f(5.0f, 5.0f, 5.0f);
    const cv::Mat coc(input.size(), CV_32FC1, cv::Scalar(4.0f));
    const cv::Mat zones = zoneMap(input, coc);
    cv::Mat truth = input.clone(), image = input.clone();
    image.at<cv::Vec3f>(70, 70) += cv::Vec3f(0.1f, 0.1f, 0.1f); // far, outside the light's 30 px
    image.at<cv::Vec3f>(20, 20) += cv::Vec3f(0.3f, 0.3f, 0.3f); // lights
    const ZoneReport report = measureZones(image, truth, zones);
    const auto lights = static_cast<std::size_t>(Zone::Lights), farZone = static_cast<std::size_t>(Zone::Far);
    EXPECT_NEAR(report.errorShare[lights], 0.09 / 0.10, 1e-6);
    EXPECT_NEAR(report.errorShare[farZone], 0.01 / 0.10, 1e-6);
    double shares = 0.0, pixels = 0.0;
    for (const Zone zone : kZones) {
        shares += report.errorShare[static_cast<std::size_t>(zone)];
        pixels += report.share[static_cast<std::size_t>(zone)];
    }
    EXPECT_NEAR(shares, 1.0, 1e-9);
    EXPECT_NEAR(pixels, 1.0, 1e-9);
    // The lights zone: the squared error 3 x 0.09 over its pixels' 3 channels.
    const double lightPixels = report.share[lights] * 80 * 80;
    EXPECT_NEAR(report.psnr[lights], psnrFromMse(0.09 / lightPixels), 1e-4); // 0.3f + 0.4f in float
    EXPECT_TRUE(std::isnan(report.psnr[static_cast<std::size_t>(Zone::Near)]));
}

} // namespace
} // namespace defocus
