// SPDX-License-Identifier: LGPL-2.1-or-later
// The depth-scale plausibility check (sources/DepthScale): millimetre depth read at TUM's 5000
// units per metre, and the reverse, give one warning with the fix; a room at the right scale none.
#include <gtest/gtest.h>

#include "sources/DepthScale.hpp"

namespace defocus {
namespace {

cv::Mat roomAt(float medianM)
{
    cv::Mat depth(30, 40, CV_32FC1, cv::Scalar(medianM));
    depth(cv::Rect(0, 0, 40, 5)).setTo(0.0f); // holes do not count
    return depth;
}

// Defect caught: a millimetre clip read at 5000 units per metre (every depth 5x too near: the
// RealSense case) passing without a word, or a fix that does not bring the depth into range.
TEST(DepthScale, MillimetresReadAsTumUnitsWarnWithTheFix)
{
    // A room at 1.4 m written in millimetres (1400) and read at 5000: 0.28 m.
    const DepthScaleCheck check = checkDepthScale(roomAt(1400.0f / 5000.0f), 5000.0, "rgb/1.png");
    EXPECT_NEAR(check.medianM, 0.28, 1e-6);
    ASSERT_TRUE(check.suggestedScale);
    EXPECT_EQ(*check.suggestedScale, 1000.0);
    EXPECT_NE(check.warning.find("rgb/1.png"), std::string::npos) << check.warning;
    EXPECT_NE(check.warning.find("--depth-scale 1000"), std::string::npos) << check.warning;
    EXPECT_NE(check.warning.find("1.40 m"), std::string::npos) << check.warning;
}

// Defect caught: depth at a far too coarse scale passing (16-bit millimetres taken as metres, as
// --depth-scale 1 gives): every depth 1000x too far, so the whole frame looks in focus at infinity.
TEST(DepthScale, FarSceneSuggestsTheScaleThatBringsItHome)
{
    const DepthScaleCheck check = checkDepthScale(roomAt(2000.0f), 1.0, "f"); // 2 m in millimetres
    ASSERT_TRUE(check.suggestedScale);
    EXPECT_EQ(*check.suggestedScale, 1000.0);
    EXPECT_NE(check.warning.find("farther"), std::string::npos) << check.warning;
    EXPECT_NE(check.warning.find("--depth-scale 1000 (median 2.00 m)"), std::string::npos) << check.warning;
}

// Defect caught: warnings for ordinary scenes (a desk at 0.6 m, a hall at 15 m) or for a frame
// with no valid depth at all.
TEST(DepthScale, PlausibleScenesAndEmptyDepthPassQuietly)
{
    for (const float metres : {0.6f, 1.4f, 4.0f, 15.0f})
        EXPECT_TRUE(checkDepthScale(roomAt(metres), 5000.0, "f").warning.empty()) << metres;
    const DepthScaleCheck none = checkDepthScale(cv::Mat(4, 4, CV_32FC1, cv::Scalar(0.0f)), 5000.0, "f");
    EXPECT_TRUE(none.warning.empty());
    EXPECT_EQ(none.validPixels, 0u);
}

} // namespace
} // namespace defocus
