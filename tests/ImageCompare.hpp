// SPDX-License-Identifier: LGPL-2.1-or-later
// Byte-for-byte image comparison for GoogleTest, over OpenCV alone (the tests of the public API
// and of the GStreamer element include it beside the installed headers).
#pragma once

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace defocus::test {

/// Success when `a` and `b` have one size and type and every sample equal; otherwise how many
/// samples differ.
inline ::testing::AssertionResult identical(const cv::Mat& a, const cv::Mat& b)
{
    if (a.size() != b.size() || a.type() != b.type())
        return ::testing::AssertionFailure() << "sizes or types differ";
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    const int differing = cv::countNonZero(diff.reshape(1));
    return differing == 0 ? ::testing::AssertionSuccess()
                          : ::testing::AssertionFailure() << differing << " samples differ";
}

} // namespace defocus::test
