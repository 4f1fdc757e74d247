// SPDX-License-Identifier: LGPL-2.1-or-later
// Helpers shared by the tests.
#include "tests/TestSupport.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <sys/wait.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "filter/Presets.hpp"
#include "sources/ImageIO.hpp"

namespace defocus::test {

std::filesystem::path dataDir()
{
    return DEFOCUS_DATA_DIR;
}

CliResult runDefocus(const std::string& arguments)
{
    const std::filesystem::path binary = std::filesystem::path(DEFOCUS_BINARY_DIR) / "defocus";
    EXPECT_TRUE(std::filesystem::exists(binary)) << binary << " is missing: build the 'defocus' target first";
    CliResult result;
    FILE* pipe = ::popen(fmt::format("'{}' {} 2>&1", binary.string(), arguments).c_str(), "r");
    if (!pipe)
        return result;
    std::array<char, 4096> chunk{};
    while (std::fgets(chunk.data(), static_cast<int>(chunk.size()), pipe))
        result.output += chunk.data();
    const int status = ::pclose(pipe);
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

Frame railingLights()
{
    const auto dir = dataDir() / "corpus" / "railing-lights";
    Frame frame;
    frame.color = readColor(dir / "color_linear.exr");
    frame.depth = readDepth(dir / "depth_mm.png", 1000.0);
    return frame;
}

std::filesystem::path scratchDir(const std::string& name)
{
    const auto dir = std::filesystem::path(DEFOCUS_BINARY_DIR) / "test-scratch" / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

LensSettings lensWithFarCoc(double diameterPx)
{
    LensSettings lens;
    lens.model = CocModel::FocalRange;
    lens.focusM = 1.0;
    lens.nearLimitM = 0.5;
    lens.farLimitM = 2.0;
    lens.maxCocPx = diameterPx;
    return lens;
}

void PrintTo(const NamedQuality& quality, std::ostream* os)
{
    *os << quality.name;
}

std::vector<NamedQuality> shippedPresets()
{
    std::vector<NamedQuality> list{{std::string(kDefaultPreset), presetSettings(kDefaultPreset)}};
    for (const QualityPreset& p : qualityPresets())
        if (p.name != kDefaultPreset)
            list.push_back({std::string(p.name), p.quality});
    return list;
}

std::vector<NamedQuality> presetsAndKernels()
{
    std::vector<NamedQuality> list = shippedPresets();
    list.push_back({"rhombi", QualitySettings{}});
    QualitySettings mcintosh;
    mcintosh.kernel = HexagonKernel::McIntoshMin;
    list.push_back({"mcintosh", mcintosh});
    return list;
}

cv::Mat foregroundReach(const cv::Mat& signedCoc, int margin)
{
    CV_Assert(signedCoc.type() == CV_32F);
    cv::Mat reach = cv::Mat::zeros(signedCoc.size(), CV_8U);
    double lowest = 0.0;
    cv::minMaxLoc(signedCoc, &lowest);
    // Near pixels by their radius rounded up, each group grown by that radius and the margin.
    for (int radius = 1; radius <= static_cast<int>(std::ceil(-lowest / 2.0)); ++radius) {
        const cv::Mat near = (signedCoc <= -0.5f) & (signedCoc > -2.0f * static_cast<float>(radius)) &
                             (signedCoc <= -2.0f * static_cast<float>(radius - 1));
        if (cv::countNonZero(near) == 0)
            continue;
        const int r = radius + margin;
        cv::Mat grown;
        cv::dilate(near, grown, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1}));
        reach |= grown;
    }
    return reach;
}

bool allFinite(const cv::Mat& m)
{
    if (m.depth() != CV_32F && m.depth() != CV_64F && m.depth() != CV_16F)
        return true;
    cv::Mat f;
    m.convertTo(f, CV_32F);
    return cv::checkRange(f);
}

} // namespace defocus::test
