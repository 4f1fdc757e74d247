// Scene analysis on the GPU (scene_analysis.comp, SceneAnalysisPass) against the CPU's
// measureScene(), which is the reference: the same tile depth ranges, histogram and highlights.
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "filter/DepthPrep.hpp"
#include "filter/Lens.hpp"
#include "filter/SceneAnalysis.hpp"
#include "filter/methods/Method.hpp"
#include "filter/passes/SceneAnalysisPass.hpp"
#include "sources/ImageIO.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

class SceneAnalysisGL : public test::GLTest {
protected:
    /// Measures `color` (CV_8UC3 or CV_32FC3) and its filled depth on the GPU and on the CPU and
    /// compares them.
    static void expectSameMeasurement(const cv::Mat& color, const cv::Mat& filledDepth, const CocCoefficients& k)
    {
        const bool eightBit = color.type() == CV_8UC3;
        gl::Texture colorTexture(eightBit ? GL_SRGB8 : GL_RGB32F, color.cols, color.rows, "test colour");
        colorTexture.upload(GL_BGR, eightBit ? GL_UNSIGNED_BYTE : GL_FLOAT, color.data);
        gl::Texture depth(GL_R32F, color.cols, color.rows, "test depth");
        depth.upload(GL_RED, GL_FLOAT, filledDepth.data);
        SceneAnalysisPass pass;
        const SceneMeasurement gpu = pass.run(depth, colorTexture, eightBit, k);
        const SceneMeasurement cpu = measureScene(filledDepth, color, k);

        ASSERT_EQ(gpu.tiles, cpu.tiles);
        EXPECT_EQ(gpu.pixels, cpu.pixels);
        // Minimum and maximum pick one of the pixels' own values: exactly equal.
        EXPECT_EQ(cv::norm(gpu.tileMinDepth, cpu.tileMinDepth, cv::NORM_INF), 0.0);
        EXPECT_EQ(cv::norm(gpu.tileMaxDepth, cpu.tileMaxDepth, cv::NORM_INF), 0.0);
        // The histogram: the GPU may fuse the CoC's multiply-add, so a pixel within a float
        // rounding of a bin edge can land in the next bin; a few pixels in a frame at most.
        int total = 0, moved = 0;
        for (std::size_t bin = 0; bin < cpu.histogram.size(); ++bin) {
            total += gpu.histogram[bin];
            moved += std::abs(gpu.histogram[bin] - cpu.histogram[bin]);
        }
        EXPECT_EQ(total, static_cast<int>(cpu.pixels));
        EXPECT_LE(moved, 4) << "pixels in another |CoC| bin than on the CPU";
        // Highlights: the same pixels (8-bit: the sRGB decode's threshold sits between codes 249
        // and 250; float: the same luminance sum, so again only pixels at rounding distance).
        EXPECT_NEAR(static_cast<double>(gpu.highlightPixels), static_cast<double>(cpu.highlightPixels), 2.0);
        // Per tile, the same (the tiles the sprites are looked for on and the CoC pass treats
        // highlights on): catches the readback taking another word or tile.
        ASSERT_EQ(gpu.tileHighlights.size(), cpu.tiles);
        EXPECT_LE(cv::norm(gpu.tileHighlights, cpu.tileHighlights, cv::NORM_L1), 2.0);
    }
};

TEST_F(SceneAnalysisGL, MatchesTheCpuOnARecordedFrame)
{
    // The TUM clip's first frame: 8-bit colour, a quarter of its depth holes (filled first).
    const auto dir = test::dataDir() / "tum_fr1_rpy";
    const cv::Mat color = readColor(dir / "rgb/1305031250.261917.png");
    const cv::Mat raw = readDepth(dir / "depth/1305031250.253735.png", 5000.0);
    const PreparedDepth depth = prepareDepth(raw, color.size(), 1.0f);
    LensSettings lens;
    lens.fNumber = 1.4;
    lens.focusM = 1.0;
    expectSameMeasurement(color, depth.metres, cocCoefficients(lens, color.cols));
}

TEST_F(SceneAnalysisGL, MatchesTheCpuOnHdrInputWithHighlights)
{
    // The Blender scene: float colour with lights up to 80, near and far blur.
    const auto dir = test::dataDir() / "blender_spheres";
    const cv::Mat color = readColor(dir / "color_linear.exr");
    const cv::Mat depth = readDepth(dir / "depth.exr", 1000.0);
    const SceneMeasurement cpu = measureScene(depth, color, cocCoefficients(blenderSpheresLens(), color.cols));
    ASSERT_GT(cpu.highlightPixels, 0u);
    expectSameMeasurement(color, depth, cocCoefficients(blenderSpheresLens(), color.cols));
}

TEST_F(SceneAnalysisGL, MatchesTheCpuOnAFrameOfOddSize)
{
    // 75 x 41: partial tiles on the right and at the bottom; random depths 0.3-20 m and
    // clipped pixels here and there.
    cv::RNG rng(7);
    cv::Mat color(41, 75, CV_8UC3), depth(41, 75, CV_32F);
    rng.fill(color, cv::RNG::UNIFORM, 0, 256);
    rng.fill(depth, cv::RNG::UNIFORM, 0.3, 20.0);
    LensSettings lens;
    lens.focusM = 2.0;
    lens.fNumber = 1.0;
    expectSameMeasurement(color, depth, cocCoefficients(lens, color.cols));
}

TEST_F(SceneAnalysisGL, HighlightTilesAreTheTilesWithAPixelAboveWhite)
{
    // Catches a tile of the list at the wrong place (column and row swapped, another tile's
    // count read back): the sprites would be looked for, and highlights treated by the CoC pass,
    // where there are none, and a light left in the gather. 75 x 41 float: tiles 5 x 3, the last
    // column and row partial; dark grey with lights at (3, 2), (17, 35) and (74, 40), and a pixel
    // just below white (luminance 0.99) in tile (2, 0), which is not one.
    cv::Mat color(41, 75, CV_32FC3, cv::Scalar::all(0.2));
    color.at<cv::Vec3f>(2, 3) = cv::Vec3f(5.0f, 5.0f, 5.0f);
    color.at<cv::Vec3f>(35, 17) = cv::Vec3f(0.0f, 3.0f, 0.0f);
    color.at<cv::Vec3f>(40, 74) = cv::Vec3f(20.0f, 20.0f, 20.0f);
    color.at<cv::Vec3f>(5, 40) = cv::Vec3f(0.99f, 0.99f, 0.99f);
    const cv::Mat depth(color.size(), CV_32F, cv::Scalar(3.0));
    LensSettings lens;
    lens.focusM = 1.0;
    const CocCoefficients k = cocCoefficients(lens, color.cols);
    const std::vector<cv::Point> expected{{0, 0}, {1, 2}, {4, 2}};

    gl::Texture colorTexture(GL_RGB32F, color.cols, color.rows, "test colour");
    colorTexture.upload(GL_BGR, GL_FLOAT, color.data);
    gl::Texture depthTexture(GL_R32F, color.cols, color.rows, "test depth");
    depthTexture.upload(GL_RED, GL_FLOAT, depth.data);
    SceneAnalysisPass pass;
    EXPECT_EQ(finishAnalysis(pass.run(depthTexture, colorTexture, false, k), k, 0.0).highlightTiles, expected);
    EXPECT_EQ(analyseScene(depth, color, k, 0.0).highlightTiles, expected);
}

TEST(ScenePlan, TapLoopsUnrollWhereMostLinesRunToTheLastTap)
{
    // Four blurred tiles; a line is half the tile's largest |CoC| (and half that again at half
    // size). With 6 taps a line of 4.5 px or more counts as running to the last tap.
    SceneAnalysis analysis;
    analysis.tiles = {4, 1};
    analysis.tileMinCoc = (cv::Mat_<float>(1, 4) << 2.0f, 2.0f, 2.0f, -20.0f);
    analysis.tileMaxCoc = (cv::Mat_<float>(1, 4) << 9.0f, 9.0f, 4.0f, 3.0f);
    analysis.tileNearDiameter = cv::Mat::zeros(1, 4, CV_32F);
    analysis.minCoc = -20.0f;
    analysis.maxCoc = 9.0f;
    // Full size: lines of 4.5, 4.5, 2 and 10 px: three of four reach 4.5.
    EXPECT_TRUE(makePlan(analysis, false, HexagonKernel::RhombiSum, Resolution::Full, 6).unrolledTaps);
    // Half size: 2.25, 2.25, 1 and 5 px: one of four.
    EXPECT_FALSE(makePlan(analysis, false, HexagonKernel::RhombiSum, Resolution::Half, 6).unrolledTaps);
    // 12 taps want 9 px: only the near tile's 10 px.
    EXPECT_FALSE(makePlan(analysis, false, HexagonKernel::RhombiSum, Resolution::Full, 12).unrolledTaps);
    // The foreground reaching a tile lengthens its lines too (the near field).
    analysis.tileNearDiameter.setTo(20.0f);
    analysis.foreground = true;
    EXPECT_TRUE(makePlan(analysis, true, HexagonKernel::RhombiSum, Resolution::Full, 12).unrolledTaps);
    // McIntosh's passes have no such variant; no tap count, no decision.
    EXPECT_FALSE(makePlan(analysis, true, HexagonKernel::McIntoshMin, Resolution::Full, 6).unrolledTaps);
    EXPECT_FALSE(makePlan(analysis, true, HexagonKernel::RhombiSum, Resolution::Full).unrolledTaps);
}

} // namespace
} // namespace defocus
