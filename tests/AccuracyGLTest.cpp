// Accuracy smoke against a path-traced thin lens: the Blender spheres scene (data/
// blender_spheres), PSNR of linear values clipped to [0, 1] against the Cycles truth.
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "filter/Pipeline.hpp"
#include "sources/ImageIO.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

class Accuracy : public test::GLTest {};

double psnrClipped(const cv::Mat& a, const cv::Mat& b)
{
    cv::Mat ca = cv::min(cv::max(a, 0.0), 1.0), cb = cv::min(cv::max(b, 0.0), 1.0);
    return cv::PSNR(ca, cb, 1.0);
}

LensSettings blenderLens()
{
    LensSettings lens;
    lens.focalLengthMm = 85.0;
    lens.fNumber = 1.4;
    lens.focusM = 5.0;
    lens.sensorWidthMm = 36.0;
    lens.maxCocPx = 64.0; // above the scene's largest CoC (46.6 px), so nothing is clamped
    return lens;
}

TEST_F(Accuracy, BlenderSpheresBeatsTheUnblurredInputByFar)
{
    const auto dir = test::dataDir() / "blender_spheres";
    const cv::Mat color = readColor(dir / "color_linear.exr");
    const cv::Mat depth = readDepth(dir / "depth.exr", 1000.0);
    const cv::Mat truth = readColor(dir / "truth_f1.4_focus5_linear.exr");
    ASSERT_EQ(color.size(), cv::Size(640, 480));

    const double unblurred = psnrClipped(color, truth);
    // The scene's documented figure for the unblurred input is 16.5 dB (half-float storage of
    // the bundled EXRs changes it by far less than 0.1 dB).
    EXPECT_NEAR(unblurred, 16.5, 0.1);

    Pipeline pipeline;
    const cv::Mat out = pipeline.run({color, depth, 0.0, 0, "blender"}, blenderLens(), {}, View::Composite,
                                     Encoding::Linear32F);
    EXPECT_TRUE(test::allFinite(out));
    const double psnr = psnrClipped(out, truth);
    std::printf("[ FIGURE   ] Blender spheres, McIntosh 16 taps, RGBA16F: %.2f dB (unblurred %.2f dB)\n", psnr,
                unblurred);
    // "Far above" the input: the plain McIntosh chain measured about 30 dB on this scene; 8 dB
    // over the input leaves room for sampling differences between drivers.
    EXPECT_GT(psnr, unblurred + 8.0);
}

} // namespace
} // namespace defocus
