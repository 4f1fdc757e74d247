// Helpers shared by the tests.
#include "tests/TestSupport.hpp"

#include <cstdlib>

namespace defocus::test {

std::filesystem::path dataDir()
{
    return DEFOCUS_DATA_DIR;
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

bool allFinite(const cv::Mat& m)
{
    if (m.depth() != CV_32F && m.depth() != CV_64F && m.depth() != CV_16F)
        return true;
    cv::Mat f;
    m.convertTo(f, CV_32F);
    return cv::checkRange(f);
}

} // namespace defocus::test
