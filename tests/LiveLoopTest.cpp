// SPDX-License-Identifier: LGPL-2.1-or-later
// The preview's frame feed without a camera: a fake live source faster than its consumer drops
// the oldest frames (counted) and never blocks; a recorded one delivers every frame; pacing and
// the latency figures.
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include "samples/LiveLoop.hpp"

namespace defocus {
namespace {

using namespace std::chrono_literals;

/// Frames every `period`, stamped on the monotonic clock like a V4L2 driver's, `count` of them.
class FakeSource : public FrameSource {
public:
    FakeSource(bool live, std::chrono::milliseconds period, std::size_t count, bool failAtEnd = false)
        : live_(live), period_(period), count_(count), failAtEnd_(failAtEnd)
    {
    }
    std::optional<Frame> next() override
    {
        if (index_ == count_) {
            if (failAtEnd_)
                throw SourceError("fake camera: unplugged (ENODEV)");
            return std::nullopt;
        }
        std::this_thread::sleep_for(period_);
        Frame frame;
        frame.color = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(static_cast<double>(index_ % 256)));
        frame.index = index_++;
        frame.timestampS = std::chrono::duration<double>(LiveClock::now().time_since_epoch()).count();
        return frame;
    }
    bool isLive() const override { return live_; }
    std::string describe() const override { return "fake"; }

private:
    bool live_;
    std::chrono::milliseconds period_;
    std::size_t count_;
    bool failAtEnd_;
    std::size_t index_ = 0;
};

TEST(FrameFeed, LiveSourceFasterThanTheConsumerDropsTheOldestFrames)
{
    FakeSource source(true, 2ms, 100000);
    FrameFeed feed(source, true);
    std::size_t taken = 0, lastIndex = 0;
    for (int i = 0; i < 10; ++i) {
        std::this_thread::sleep_for(30ms); // a slow filter
        const auto start = LiveClock::now();
        const auto fed = feed.next(100ms);
        ASSERT_TRUE(fed);
        // The newest frame is there already: no waiting.
        // (Bounds well above the 2 ms period leave room for a loaded machine.)
        EXPECT_LT(LiveClock::now() - start, 50ms);
        EXPECT_TRUE(fed->fromCaptureClock);
        EXPECT_LT(LiveClock::now() - fed->origin, 100ms) << "not the newest frame";
        if (taken > 0) {
            EXPECT_GT(fed->frame.index, lastIndex + 3) << "frames in between should have been dropped";
        }
        lastIndex = fed->frame.index;
        ++taken;
    }
    feed.stop();
    // Every frame read was either taken, dropped, or is the one left in the slot.
    const std::size_t captured = feed.captured(), dropped = feed.dropped();
    EXPECT_GT(dropped, 50u);
    EXPECT_GE(captured, taken + dropped);
    EXPECT_LE(captured, taken + dropped + 1);
}

TEST(FrameFeed, LiveNextNeverWaitsLongerThanItsTimeout)
{
    FakeSource source(true, 300ms, 100000); // a stalled camera
    FrameFeed feed(source, true);
    const auto start = LiveClock::now();
    EXPECT_FALSE(feed.next(20ms));
    EXPECT_LT(LiveClock::now() - start, 150ms);
    EXPECT_FALSE(feed.ended());
}

TEST(FrameFeed, RecordedSourceDeliversEveryFrameToASlowConsumer)
{
    FakeSource source(false, 1ms, 12);
    FrameFeed feed(source, false);
    std::size_t expected = 0;
    while (const auto fed = feed.next(0ms)) {
        std::this_thread::sleep_for(5ms);
        EXPECT_EQ(fed->frame.index, expected++);
        EXPECT_FALSE(fed->fromCaptureClock);
    }
    EXPECT_EQ(expected, 12u);
    EXPECT_TRUE(feed.ended());
    EXPECT_EQ(feed.dropped(), 0u);
}

TEST(FrameFeed, LiveStreamEndAndErrorsReachTheConsumer)
{
    {
        FakeSource source(true, 1ms, 3);
        FrameFeed feed(source, true);
        const auto deadline = LiveClock::now() + 2s;
        while (!feed.ended() && LiveClock::now() < deadline)
            feed.next(10ms);
        EXPECT_TRUE(feed.ended());
    }
    {
        FakeSource source(true, 1ms, 2, true);
        FrameFeed feed(source, true);
        std::this_thread::sleep_for(50ms);
        const auto last = feed.next(10ms); // the frame before the error still arrives
        ASSERT_TRUE(last);
        EXPECT_THROW(feed.next(10ms), SourceError);
    }
}

TEST(FrameFeed, FramesReplacedWhilePausedAreNotCountedAsDropped)
{
    FakeSource source(true, 2ms, 100000);
    FrameFeed feed(source, true);
    feed.setPaused(true);
    std::this_thread::sleep_for(60ms);
    EXPECT_EQ(feed.dropped(), 0u);
    EXPECT_GT(feed.captured(), 5u);
    // Playing again: the frame waiting is at most one period old, and a slow consumer drops again.
    feed.setPaused(false);
    ASSERT_TRUE(feed.next(100ms));
    std::this_thread::sleep_for(60ms);
    EXPECT_GT(feed.dropped(), 5u);
}

TEST(Pacer, ClipPlaysNoFasterThanItWasRecordedAndNeverCatchesUp)
{
    Pacer pacer(1.0 / 30);
    const auto start = LiveClock::now();
    for (int i = 0; i < 5; ++i)
        pacer.wait(100.0 + 0.05 * i); // 50 ms apart
    EXPECT_GE(LiveClock::now() - start, 195ms);
    // A consumer that fell behind by 200 ms is not made to rush: the next frame still waits
    // its interval after the previous one was taken.
    std::this_thread::sleep_for(200ms);
    pacer.wait(100.25);
    const auto taken = LiveClock::now();
    pacer.wait(100.30);
    EXPECT_GE(LiveClock::now() - taken, 45ms);
}

TEST(LiveStats, PercentilesAndFps)
{
    LiveStats stats;
    const auto t0 = LiveClock::now();
    for (int i = 0; i < 11; ++i) // shown every 100 ms, 10..20 ms after their origin
        stats.frameShown(t0 + i * 100ms - (10 + i) * 1ms, t0 + i * 100ms);
    EXPECT_NEAR(stats.fps(), 10.0, 1e-6);
    EXPECT_NEAR(stats.recentFps(), 10.0, 1e-6);
    EXPECT_NEAR(stats.latencyPercentileMs(0.5), 15.0, 1e-6);
    EXPECT_NEAR(stats.latencyPercentileMs(1.0), 20.0, 1e-6);
    EXPECT_NEAR(stats.recentLatencyMs(2), 19.5, 1e-6);
}

TEST(LiveStats, CaptureTimesOnlyFromTheMonotonicClock)
{
    const auto now = LiveClock::now();
    const double nowS = std::chrono::duration<double>(now.time_since_epoch()).count();
    ASSERT_TRUE(captureTime(nowS - 0.030, now));
    EXPECT_NEAR(std::chrono::duration<double>(now - *captureTime(nowS - 0.030, now)).count(), 0.030, 1e-6);
    EXPECT_FALSE(captureTime(1305031250.26, now)); // a TUM file time (Unix epoch)
    EXPECT_FALSE(captureTime(0.0, now));
    EXPECT_FALSE(captureTime(nowS + 1.0, now));    // in the future
}

} // namespace
} // namespace defocus
