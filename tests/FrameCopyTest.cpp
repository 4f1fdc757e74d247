// SPDX-License-Identifier: LGPL-2.1-or-later
// Frame-sized copies to and from mapped buffers (gl::copyFrameBytes): in stripes on OpenCV's
// threads above two stripes, one memcpy below. Needs no GL.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "filter/gl/Objects.hpp"

namespace defocus {
namespace {

// Defects caught: a stripe left out or copied to another stripe's place, the last (short) stripe
// cut off or run past the end, bytes written before the destination; at the sizes where the
// copy changes from one memcpy to stripes, and from and to addresses off any alignment.
TEST(FrameCopy, EveryByteArrivesAndNoneBeyond)
{
    constexpr std::size_t kMiB = std::size_t{1} << 20;
    constexpr std::size_t kGuard = 64;
    constexpr std::uint8_t kUntouched = 0xAB;
    for (const std::size_t bytes : {std::size_t{0}, std::size_t{1}, kMiB, 2 * kMiB - 1, 2 * kMiB, 2 * kMiB + 1,
                                    5 * kMiB + kMiB / 2 + 3, 9 * kMiB})
        for (const std::size_t offset : {std::size_t{0}, std::size_t{3}}) {
            SCOPED_TRACE(testing::Message() << bytes << " bytes, offset " << offset);
            cv::Mat source(1, static_cast<int>(bytes + offset + 1), CV_8UC1);
            cv::randu(source, 0, 256);
            std::vector<std::uint8_t> target(kGuard + bytes + kGuard, kUntouched);
            gl::copyFrameBytes(target.data() + kGuard + offset / 3, source.data + offset, bytes);
            const std::uint8_t* in = source.data + offset;
            const std::uint8_t* out = target.data() + kGuard + offset / 3;
            std::size_t wrong = 0;
            for (std::size_t i = 0; i < bytes; ++i)
                wrong += out[i] != in[i] ? 1 : 0;
            EXPECT_EQ(wrong, 0u);
            for (std::size_t i = 0; i < kGuard + offset / 3; ++i)
                ASSERT_EQ(target[i], kUntouched) << "written before the destination";
            for (std::size_t i = kGuard + offset / 3 + bytes; i < target.size(); ++i)
                ASSERT_EQ(target[i], kUntouched) << "written past the end";
        }
}

} // namespace
} // namespace defocus
