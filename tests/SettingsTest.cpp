// SPDX-License-Identifier: LGPL-2.1-or-later
// Parameter validation: one place, messages naming parameter, value and range; clamping.
#include <cmath>

#include <gtest/gtest.h>

#include "filter/Settings.hpp"

namespace defocus {
namespace {

TEST(Settings, DefaultsAreValid)
{
    LensSettings lens;
    QualitySettings quality;
    EXPECT_TRUE(validate(lens).empty());
    EXPECT_TRUE(validate(quality).empty());
}

TEST(Settings, MessageNamesParameterValueAndRange)
{
    LensSettings lens;
    lens.fNumber = 0.5;
    const auto issues = validate(lens);
    ASSERT_EQ(issues.size(), 1u);
    EXPECT_EQ(issues[0].parameter, "--f-number");
    EXPECT_NE(issues[0].message.find("0.5"), std::string::npos);
    EXPECT_NE(issues[0].message.find("between 0.7 and 64"), std::string::npos);
    EXPECT_DOUBLE_EQ(lens.fNumber, 0.5) << "without clamp the value is left alone";
}

TEST(Settings, FocusMustBeBeyondFocalLength)
{
    LensSettings lens;
    lens.focalLengthMm = 50.0;
    lens.focusM = 0.05; // equal to the focal length
    ASSERT_EQ(validate(lens).size(), 1u);
    lens.focusM = 0.01; // below it
    ASSERT_EQ(validate(lens).size(), 1u);
    lens.focusM = std::numeric_limits<double>::infinity();
    EXPECT_TRUE(validate(lens).empty());
}

TEST(Settings, ClampModeFixesEveryValueAndStillReports)
{
    LensSettings lens;
    lens.fNumber = 100.0;
    lens.focalLengthMm = 0.1;
    lens.maxCocPx = -3.0;
    lens.sensorWidthMm = std::nan("");
    QualitySettings quality;
    quality.samples = 1000;
    EXPECT_EQ(validate(lens, true).size(), 4u);
    EXPECT_EQ(validate(quality, true).size(), 1u);
    EXPECT_DOUBLE_EQ(lens.fNumber, 64.0);
    EXPECT_DOUBLE_EQ(lens.focalLengthMm, 1.0);
    EXPECT_DOUBLE_EQ(lens.maxCocPx, 0.0);
    EXPECT_DOUBLE_EQ(lens.sensorWidthMm, 1.0);
    EXPECT_EQ(quality.samples, 64);
    EXPECT_TRUE(validate(lens).empty());
    EXPECT_TRUE(validate(quality).empty());
}

TEST(Settings, FocusParsesMetresInfinityAndAuto)
{
    LensSettings lens;
    bool isAuto = true;
    ASSERT_TRUE(parseFocus("1.25", lens, isAuto));
    EXPECT_FALSE(isAuto);
    EXPECT_DOUBLE_EQ(lens.focusM, 1.25);
    ASSERT_TRUE(parseFocus("inf", lens, isAuto));
    EXPECT_TRUE(std::isinf(lens.focusM));
    ASSERT_TRUE(parseFocus("auto", lens, isAuto));
    EXPECT_TRUE(isAuto);
    lens.focusM = 3.0;
    EXPECT_FALSE(parseFocus("3m", lens, isAuto)) << "trailing text is not a distance";
    EXPECT_FALSE(parseFocus("abc", lens, isAuto));
    EXPECT_FALSE(parseFocus("", lens, isAuto));
    EXPECT_DOUBLE_EQ(lens.focusM, 3.0) << "a rejected value leaves the lens alone";
}

TEST(Settings, CommandLineCheckAcceptsAutoFocusButNotABadOne)
{
    LensSettings lens;
    lens.focusM = 0.01; // below the 50 mm focal length
    EXPECT_EQ(validateCommandLine(lens, {}, false).size(), 1u);
    EXPECT_TRUE(validateCommandLine(lens, {}, true).empty()) << "auto focus is chosen later";
    QualitySettings quality;
    quality.samples = 1;
    EXPECT_EQ(validateCommandLine(lens, quality, true).size(), 1u);
}

TEST(Settings, ViewNamesRoundTrip)
{
    for (const View v : kAllViews) {
        View parsed = View::Input;
        ASSERT_TRUE(parseView(viewName(v), parsed));
        EXPECT_EQ(parsed, v);
    }
    View unused{};
    EXPECT_FALSE(parseView("blurry", unused));
}

} // namespace
} // namespace defocus
