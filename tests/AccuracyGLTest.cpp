// SPDX-License-Identifier: LGPL-2.1-or-later
// Accuracy smoke against a path-traced thin lens: the Blender spheres scene (data/
// blender_spheres), PSNR of linear values clipped to [0, 1] against the Cycles truth.
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "bench/methods/Method.hpp"
#include "filter/Pipeline.hpp"
#include "filter/Presets.hpp"
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

TEST_F(Accuracy, BalancedPresetIsCloserToTheLensThanBlendersDefocusNode)
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
    const cv::Mat out = pipeline.run({color, depth, 0.0, 0, "blender"}, blenderSpheresLens(), presetSettings("balanced"),
                                     View::Composite, Encoding::Linear32F);
    EXPECT_TRUE(test::allFinite(out));
    const double psnr = psnrClipped(out, truth);

    // McIntosh et al.'s chain as published: 16 taps, flat top (its first pass horizontal).
    QualitySettings published;
    published.kernel = HexagonKernel::McIntoshMin;
    published.samples = 16;
    LensSettings flatTop = blenderSpheresLens();
    flatTop.bladeRotationDeg = 30.0;
    const double mcintosh =
        psnrClipped(pipeline.run({color, depth, 0.0, 0, "blender"}, flatTop, published, View::Composite,
                                 Encoding::Linear32F),
                    truth);
    std::printf("[ FIGURE   ] Blender spheres: balanced preset %.2f dB, McIntosh 16 taps as published %.2f dB "
                "(unblurred %.2f dB)\n",
                psnr, mcintosh, unblurred);
    // The claim of docs/accuracy.md: the default preset is closer to the path-traced lens than
    // Blender's compositor Defocus node at its best (32.9 dB, quoted by the scene's README), and
    // over the 33 dB target. Measured 35.42 dB on llvmpipe; other drivers' rounding moves such
    // figures by a few hundredths of a dB, so 35 also guards against a regression.
    EXPECT_GT(psnr, 32.9);
    EXPECT_GT(psnr, 33.0);
    EXPECT_GT(psnr, 35.0);
    // And the published chain stays where it was measured (30.55 dB, docs/figures.md), 4.6 dB under it: 2 dB of
    // margin between the two, so a regression of either kernel shows.
    EXPECT_GT(mcintosh, unblurred + 8.0);
    EXPECT_GT(psnr, mcintosh + 2.0);
}

TEST_F(Accuracy, HighPresetReaches35dB)
{
    const auto dir = test::dataDir() / "blender_spheres";
    const cv::Mat color = readColor(dir / "color_linear.exr");
    const cv::Mat depth = readDepth(dir / "depth.exr", 1000.0);
    const cv::Mat truth = readColor(dir / "truth_f1.4_focus5_linear.exr");
    Pipeline pipeline;
    const cv::Mat out = pipeline.run({color, depth, 0.0, 0, "blender"}, blenderSpheresLens(), presetSettings("high"),
                                     View::Composite, Encoding::Linear32F);
    const double psnr = psnrClipped(out, truth);
    std::printf("[ FIGURE   ] Blender spheres: high preset %.2f dB\n", psnr);
    // Target: at least 35 dB. Measured 36.72 dB on llvmpipe (the CPU reference that scatters
    // every pixel's exact hexagon: 35.62); 36.2 guards against a regression with room for other
    // drivers' rounding.
    EXPECT_GT(psnr, 35.0);
    EXPECT_GT(psnr, 36.2);
}

} // namespace
} // namespace defocus
