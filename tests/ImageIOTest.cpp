// SPDX-License-Identifier: LGPL-2.1-or-later
// readColor / readDepth: bit depths, channel layouts, depth scales and the errors for bad files.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "sources/FrameSource.hpp"
#include "sources/ImageIO.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

// Fixtures are written with OpenCV directly, before the code under test has run, so EXR must be
// switched on here too (ctest sets it; a direct run of the binary does not).
void writeFixture(const fs::path& file, const cv::Mat& image)
{
    enableOpenExr();
    ASSERT_TRUE(cv::imwrite(file.string(), image)) << file;
}

// The sRGB EOTF written out independently of the code under test.
double srgbToLinear(double c)
{
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

std::string messageOf(const std::function<void()>& call)
{
    try {
        call();
    } catch (const SourceError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no SourceError thrown";
    return {};
}

TEST(ImageIO, SixteenBitDepthIsDividedByTheScaleAndZeroStaysZero)
{
    const fs::path file = test::scratchDir("ImageIO_depth16") / "depth.png";
    cv::Mat raw(1, 4, CV_16UC1);
    raw.at<std::uint16_t>(0, 0) = 0;
    raw.at<std::uint16_t>(0, 1) = 5000;
    raw.at<std::uint16_t>(0, 2) = 12345;
    raw.at<std::uint16_t>(0, 3) = 65535;
    writeFixture(file, raw);

    const cv::Mat metres = readDepth(file, 5000.0);
    ASSERT_EQ(metres.type(), CV_32FC1);
    ASSERT_EQ(metres.size(), raw.size());
    EXPECT_EQ(metres.at<float>(0, 0), 0.0f);
    EXPECT_FLOAT_EQ(metres.at<float>(0, 1), 1.0f);
    EXPECT_FLOAT_EQ(metres.at<float>(0, 2), 2.469f);
    EXPECT_FLOAT_EQ(metres.at<float>(0, 3), 13.107f);

    const cv::Mat millimetres = readDepth(file, 1000.0);
    EXPECT_FLOAT_EQ(millimetres.at<float>(0, 1), 5.0f);
}

TEST(ImageIO, FloatExrDepthIsMetresAsStored)
{
    const fs::path dir = test::scratchDir("ImageIO_depthExr");
    cv::Mat stored(2, 3, CV_32FC1);
    const float values[] = {1.43f, 5.0f, 30.0f, 0.0f, 123.25f, 0.001f};
    std::copy(std::begin(values), std::end(values), stored.ptr<float>());
    writeFixture(dir / "depth.exr", stored);

    const cv::Mat metres = readDepth(dir / "depth.exr", 5000.0); // the scale applies to 16-bit only
    ASSERT_EQ(metres.type(), CV_32FC1);
    EXPECT_EQ(cv::norm(metres, stored, cv::NORM_INF), 0.0);

    // Depth replicated in three channels (as renderers often save it): the first is taken.
    cv::Mat rgb;
    cv::merge(std::vector<cv::Mat>{stored, stored * 2.0f, stored * 3.0f}, rgb);
    writeFixture(dir / "depth3.exr", rgb);
    const cv::Mat first = readDepth(dir / "depth3.exr", 1000.0);
    ASSERT_EQ(first.type(), CV_32FC1);
    EXPECT_EQ(cv::norm(first, stored, cv::NORM_INF), 0.0);
}

TEST(ImageIO, BundledTumDepthIsMetresWithHoles)
{
    const cv::Mat depth =
        readDepth(test::dataDir() / "tum_fr1_rpy/depth/1305031250.253735.png", 5000.0);
    ASSERT_EQ(depth.type(), CV_32FC1);
    EXPECT_EQ(depth.cols, 640);
    EXPECT_EQ(depth.rows, 480);
    EXPECT_TRUE(test::allFinite(depth));
    double lo = 0.0;
    double hi = 0.0;
    cv::minMaxLoc(depth, &lo, &hi);
    EXPECT_EQ(lo, 0.0); // holes: no measurement
    EXPECT_GT(hi, 0.5); // an office: walls within a few metres
    EXPECT_LT(hi, 10.0);
    const double holes = 1.0 - cv::countNonZero(depth) / static_cast<double>(depth.total());
    EXPECT_GT(holes, 0.01);
    EXPECT_LT(holes, 0.6);
}

TEST(ImageIO, SixteenBitColourIsDecodedToLinearFloat)
{
    const fs::path file = test::scratchDir("ImageIO_color16") / "color16.png";
    // B, G, R chosen on both branches of the EOTF and at the ends.
    const std::uint16_t b = 1000;  // c = 0.01526: linear segment
    const std::uint16_t g = 32768; // c = 0.50001: power segment
    const std::uint16_t r = 65535; // 1.0
    cv::Mat raw(2, 2, CV_16UC3, cv::Scalar(b, g, r));
    raw.at<cv::Vec3w>(1, 1) = cv::Vec3w(0, 0, 0);
    writeFixture(file, raw);

    const cv::Mat linear = readColor(file);
    ASSERT_EQ(linear.type(), CV_32FC3);
    const cv::Vec3f px = linear.at<cv::Vec3f>(0, 0);
    EXPECT_NEAR(px[0], srgbToLinear(b / 65535.0), 1e-7);
    EXPECT_NEAR(px[0], 0.0011809, 1e-6); // 1000 / 65535 / 12.92
    EXPECT_NEAR(px[1], srgbToLinear(g / 65535.0), 1e-6);
    EXPECT_NEAR(px[1], 0.2140, 1e-3); // mid-grey code value is about 21 % linear
    EXPECT_EQ(px[2], 1.0f);
    EXPECT_EQ(linear.at<cv::Vec3f>(1, 1), cv::Vec3f(0, 0, 0));
}

TEST(ImageIO, EightBitGreyAndAlphaBecomeBgr)
{
    const fs::path dir = test::scratchDir("ImageIO_color8");
    writeFixture(dir / "grey.png", cv::Mat(3, 5, CV_8UC1, cv::Scalar(77)));
    const cv::Mat grey = readColor(dir / "grey.png");
    ASSERT_EQ(grey.type(), CV_8UC3);
    EXPECT_EQ(grey.size(), cv::Size(5, 3));
    EXPECT_EQ(grey.at<cv::Vec3b>(2, 4), cv::Vec3b(77, 77, 77));

    writeFixture(dir / "bgra.png", cv::Mat(3, 5, CV_8UC4, cv::Scalar(10, 20, 30, 128)));
    const cv::Mat bgra = readColor(dir / "bgra.png");
    ASSERT_EQ(bgra.type(), CV_8UC3);
    EXPECT_EQ(bgra.at<cv::Vec3b>(1, 1), cv::Vec3b(10, 20, 30)); // alpha dropped, not blended

    const cv::Mat tum = readColor(test::dataDir() / "tum_fr1_rpy/rgb/1305031250.261917.png");
    EXPECT_EQ(tum.type(), CV_8UC3);
    EXPECT_EQ(tum.size(), cv::Size(640, 480));
}

TEST(ImageIO, FloatExrColourKeepsHdrValues)
{
    const fs::path file = test::scratchDir("ImageIO_colorExr") / "hdr.exr";
    cv::Mat hdr(4, 4, CV_32FC3, cv::Scalar(0.25, 2.5, 80.0));
    writeFixture(file, hdr);
    const cv::Mat color = readColor(file);
    ASSERT_EQ(color.type(), CV_32FC3);
    EXPECT_EQ(color.at<cv::Vec3f>(3, 3), cv::Vec3f(0.25f, 2.5f, 80.0f));
}

TEST(ImageIO, EightBitDepthIsRejectedNamingFileAndFormat)
{
    const fs::path file = test::scratchDir("ImageIO_depth8") / "depth8.png";
    writeFixture(file, cv::Mat(4, 4, CV_8UC1, cv::Scalar(100)));
    const std::string message = messageOf([&] { readDepth(file, 1000.0); });
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find("8-bit"), std::string::npos) << message;
    EXPECT_NE(message.find("1 channel"), std::string::npos) << message;

    // A 16-bit colour image is not depth either.
    writeFixture(file.parent_path() / "color16.png", cv::Mat(4, 4, CV_16UC3, cv::Scalar(1, 2, 3)));
    const std::string colour =
        messageOf([&] { readDepth(file.parent_path() / "color16.png", 1000.0); });
    EXPECT_NE(colour.find("16-bit unsigned with 3 channels"), std::string::npos) << colour;
}

TEST(ImageIO, TruncatedAndCorruptFilesGiveSourceErrorNamingThePath)
{
    const fs::path dir = test::scratchDir("ImageIO_corrupt");
    const fs::path original = test::dataDir() / "tum_fr1_rpy/rgb/1305031250.261917.png";
    std::ifstream in(original, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    ASSERT_GT(bytes.size(), 1000u);

    const fs::path truncated = dir / "truncated.png";
    std::ofstream(truncated, std::ios::binary).write(bytes.data(), 600);
    const std::string t = messageOf([&] { readColor(truncated); });
    EXPECT_NE(t.find("cannot read colour image '" + truncated.string() + "'"), std::string::npos)
        << t;

    const fs::path garbage = dir / "garbage.png";
    std::ofstream(garbage) << "this is not a PNG file\n";
    const std::string g = messageOf([&] { readDepth(garbage, 5000.0); });
    EXPECT_NE(g.find("cannot read depth image '" + garbage.string() + "'"), std::string::npos)
        << g;

    const fs::path missing = dir / "missing.png";
    const std::string m = messageOf([&] { readColor(missing); });
    EXPECT_NE(m.find(missing.string()), std::string::npos) << m;
    EXPECT_NE(m.find("does not exist"), std::string::npos) << m;
}

TEST(ImageIO, DecodingFromMemoryMatchesReadingTheFile)
{
    const fs::path dir = test::scratchDir("ImageIO_memory");
    cv::Mat depth(6, 8, CV_16UC1);
    cv::randu(depth, 0, 60000);
    writeFixture(dir / "depth.png", depth);
    cv::Mat hdr(6, 8, CV_32FC3);
    cv::randu(hdr, 0.0f, 50.0f);
    writeFixture(dir / "color.exr", hdr);
    const auto bytesOf = [](const fs::path& file) {
        std::ifstream in(file, std::ios::binary);
        return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), {});
    };

    const cv::Mat fromMemory = decodeDepth(bytesOf(dir / "depth.png"), 1000.0, "mem.png");
    EXPECT_EQ(cv::norm(fromMemory, readDepth(dir / "depth.png", 1000.0), cv::NORM_INF), 0.0);
    const cv::Mat colour = decodeColor(bytesOf(dir / "color.exr"), "mem.exr");
    EXPECT_EQ(cv::norm(colour, readColor(dir / "color.exr"), cv::NORM_INF), 0.0);

    // The pixel limit is checked on the header: one pixel less than the image is refused.
    const std::string message = messageOf([&] { decodeColor(bytesOf(dir / "color.exr"), "mem.exr", 47); });
    EXPECT_NE(message.find("cannot read colour image 'mem.exr': the OpenEXR header gives 8x6 pixels, more than "
                           "the 47 allowed"),
              std::string::npos)
        << message;
}

TEST(ImageIO, NonPositiveDepthScaleIsRejected)
{
    const fs::path file = test::dataDir() / "tum_fr1_rpy/depth/1305031250.253735.png";
    EXPECT_THROW(readDepth(file, 0.0), SourceError);
    EXPECT_THROW(readDepth(file, -5000.0), SourceError);
    EXPECT_THROW(readDepth(file, std::numeric_limits<double>::quiet_NaN()), SourceError);
}

} // namespace
} // namespace defocus
