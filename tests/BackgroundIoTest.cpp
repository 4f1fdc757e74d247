// SPDX-License-Identifier: LGPL-2.1-or-later
// Reading ahead and writing behind on threads of their own (ReadAheadSource, BackgroundSink):
// every frame once, in order, the errors where the caller expects them, and bounded queues.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "sinks/BackgroundSink.hpp"
#include "sources/ReadAheadSource.hpp"

namespace defocus {
namespace {

using namespace std::chrono_literals;

// Frames 0..count-1 (the index in the frame and in its one pixel), then the end, or `error`
// thrown in place of frame `failAt`.
class CountingSource final : public FrameSource {
public:
    CountingSource(std::size_t count, std::optional<std::size_t> failAt = std::nullopt, bool busy = false)
        : count_(count), failAt_(failAt), busy_(busy)
    {
    }
    std::optional<Frame> next() override
    {
        const std::size_t i = reads++;
        if (failAt_ && i == *failAt_) {
            if (busy_)
                throw DeviceBusy("busy at frame " + std::to_string(i));
            throw SourceError("cannot read frame " + std::to_string(i));
        }
        if (i >= count_)
            return std::nullopt;
        Frame frame;
        frame.color = cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(static_cast<double>(i)));
        frame.index = i;
        return frame;
    }
    std::optional<std::size_t> frameCount() const override { return count_; }
    std::string describe() const override { return "counting source"; }
    std::atomic<std::size_t> reads{0};

private:
    std::size_t count_;
    std::optional<std::size_t> failAt_;
    bool busy_;
};

TEST(ReadAheadSource, GivesEveryFrameOnceInOrderThenTheEnd)
{
    ReadAheadSource source(std::make_unique<CountingSource>(25));
    EXPECT_EQ(source.frameCount(), 25u);
    EXPECT_EQ(source.describe(), "counting source");
    for (std::size_t i = 0; i < 25; ++i) {
        const std::optional<Frame> frame = source.next();
        ASSERT_TRUE(frame) << i;
        EXPECT_EQ(frame->index, i);
        EXPECT_EQ(frame->color.at<cv::Vec3b>(0, 0)[0], i);
    }
    EXPECT_FALSE(source.next());
    EXPECT_FALSE(source.next());
}

/// Frames 0 to `frames` - 1 in order from `source`, then its SourceError, then nothing.
void expectFramesThenTheError(ReadAheadSource& source, std::size_t frames)
{
    for (std::size_t i = 0; i < frames; ++i) {
        const std::optional<Frame> frame = source.next();
        ASSERT_TRUE(frame) << i;
        EXPECT_EQ(frame->index, i);
    }
    EXPECT_THROW(source.next(), SourceError);
    EXPECT_FALSE(source.next());
}

// The frames before a bad one are still given (nothing read is lost), then the source's own
// error, of its own type: the programs' exit status depends on it (DeviceBusy: 75).
TEST(ReadAheadSource, RethrowsTheSourcesErrorAfterTheFramesBeforeIt)
{
    // Read ahead as far as the error before a frame is taken.
    ReadAheadSource source(std::make_unique<CountingSource>(10, 3), 4);
    std::this_thread::sleep_for(150ms);
    expectFramesThenTheError(source, 3);

    ReadAheadSource busy(std::make_unique<CountingSource>(10, 0, true));
    EXPECT_THROW(busy.next(), DeviceBusy);
}

// A clip is read no further ahead than asked (not a whole video into memory), and reading goes
// on as frames are taken.
TEST(ReadAheadSource, ReadsAtMostItsDepthAhead)
{
    auto counting = std::make_unique<CountingSource>(100);
    const CountingSource& reads = *counting;
    ReadAheadSource source(std::move(counting), 2);
    // Waits for the reads expected (a loaded machine may be slow to run the thread), then gives
    // the thread time to read one too many.
    const auto settled = [&](std::size_t expected) {
        for (int i = 0; i < 500 && reads.reads.load() < expected; ++i)
            std::this_thread::sleep_for(10ms);
        std::this_thread::sleep_for(100ms);
        return reads.reads.load();
    };
    EXPECT_EQ(settled(2), 2u);
    ASSERT_TRUE(source.next());
    EXPECT_EQ(settled(3), 3u);
}

// Frames 0..count-1 handed out as reads that take a few milliseconds each, later frames often
// sooner than earlier ones (so they finish out of order), counting the reads under way at once;
// the read of frame `failAt` throws.
class SlowReadsSource final : public FrameSource {
public:
    explicit SlowReadsSource(std::size_t count, std::optional<std::size_t> failAt = std::nullopt)
        : count_(count), failAt_(failAt)
    {
    }
    std::optional<Frame> next() override
    {
        const std::optional<Read> read = nextRead();
        return read ? (*read)() : std::nullopt;
    }
    std::optional<Read> nextRead() override
    {
        if (handedOut >= count_)
            return std::nullopt;
        const std::size_t i = handedOut++;
        return [this, i] {
            const int now = ++underWay;
            int most = mostUnderWay.load();
            while (now > most && !mostUnderWay.compare_exchange_weak(most, now)) {
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(1 + (i * 7) % 6));
            --underWay;
            if (failAt_ && i == *failAt_)
                throw SourceError("cannot read frame " + std::to_string(i));
            Frame frame;
            frame.color = cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(static_cast<double>(i)));
            frame.index = i;
            return std::optional<Frame>(frame);
        };
    }
    std::string describe() const override { return "slow reads"; }
    std::atomic<std::size_t> handedOut{0};
    std::atomic<int> underWay{0};
    std::atomic<int> mostUnderWay{0};

private:
    std::size_t count_;
    std::optional<std::size_t> failAt_;
};

// Defects caught: frames given in the order their reads finished instead of the stream's; the
// reads run one at a time although threads were asked for; more read ahead than the depth.
TEST(ReadAheadSource, ReadsSideBySideGiveTheFramesInStreamOrder)
{
    auto slow = std::make_unique<SlowReadsSource>(60);
    const SlowReadsSource& reads = *slow;
    ReadAheadSource source(std::move(slow), 5, 4);
    for (std::size_t i = 0; i < 60; ++i) {
        const std::optional<Frame> frame = source.next();
        ASSERT_TRUE(frame) << i;
        EXPECT_EQ(frame->index, i);
        EXPECT_LE(reads.handedOut.load(), i + 1 + 5) << "at most the depth ahead of what was taken";
    }
    EXPECT_FALSE(source.next());
    EXPECT_FALSE(source.next());
    EXPECT_GT(reads.mostUnderWay.load(), 1) << "the reads ran side by side";
    EXPECT_LE(reads.mostUnderWay.load(), 4);
}

// Defects caught: a failed read's later frames (finished before it) given after the error, or
// the frames before it lost; the error not rethrown; a reader stopped mid-stream that hangs.
TEST(ReadAheadSource, AFailedReadComesAfterTheFramesBeforeItAndNothingAfter)
{
    ReadAheadSource source(std::make_unique<SlowReadsSource>(40, 9), 6, 3);
    expectFramesThenTheError(source, 9);

    // Stopped with reads under way: the destructor waits for them and returns.
    ReadAheadSource stopped(std::make_unique<SlowReadsSource>(1000), 8, 4);
    ASSERT_TRUE(stopped.next());
}

// Records the value of each frame's pixel; throws on write number `failAt`; waits before each
// write while `hold` is set.
class RecordingSink final : public FrameSink {
public:
    explicit RecordingSink(std::optional<std::size_t> failAt = std::nullopt) : failAt_(failAt) {}
    SinkEncoding encoding() const override { return SinkEncoding::Srgb8; }
    void write(const cv::Mat& image) override
    {
        std::unique_lock lock(mutex);
        released.wait(lock, [&] { return !hold; });
        if (failAt_ && attempts++ == *failAt_)
            throw SinkError("cannot write 'frame " + std::to_string(values.size()) + "'");
        values.push_back(image.at<cv::Vec3b>(0, 0)[0]);
    }
    void finish() override
    {
        const std::lock_guard lock(mutex);
        ++finishes;
    }
    std::filesystem::path abandon(bool keep) override
    {
        const std::lock_guard lock(mutex);
        ++abandons;
        return keep ? "kept" : "";
    }
    std::size_t framesWritten() const override { return values.size(); }
    std::string describe() const override { return "recording sink"; }

    std::mutex mutex;
    std::condition_variable released;
    bool hold = false;
    std::vector<int> values;
    int finishes = 0;
    int abandons = 0;

private:
    std::optional<std::size_t> failAt_;
    std::size_t attempts = 0;
};

cv::Mat pixel(int value)
{
    return cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(value));
}

void release(RecordingSink& inner)
{
    {
        const std::lock_guard lock(inner.mutex);
        inner.hold = false;
    }
    inner.released.notify_all();
}

// finish() returns once every frame given is written, in order, and the output finalised: the
// frames still queued when it is called too (those of a clip stopped by Ctrl-C).
TEST(BackgroundSink, WritesEveryFrameInOrderBeforeFinishReturns)
{
    auto recording = std::make_unique<RecordingSink>();
    RecordingSink& inner = *recording;
    BackgroundSink sink(std::move(recording), 4);
    Frame origin;
    for (int i = 0; i < 36; ++i)
        sink.writeFrame(pixel(i), origin);
    // The last four: one being written, held, three queued when finish() is called.
    for (int i = 0; i < 500 && sink.framesWritten() < 36; ++i)
        std::this_thread::sleep_for(10ms);
    ASSERT_EQ(sink.framesWritten(), 36u);
    {
        const std::lock_guard lock(inner.mutex);
        inner.hold = true;
    }
    for (int i = 36; i < 40; ++i)
        sink.writeFrame(pixel(i), origin);
    std::thread releaser([&] {
        std::this_thread::sleep_for(100ms);
        release(inner);
    });
    sink.finish();
    releaser.join();
    std::vector<int> expected(40);
    for (int i = 0; i < 40; ++i)
        expected[static_cast<std::size_t>(i)] = i;
    EXPECT_EQ(inner.values, expected);
    EXPECT_EQ(sink.framesWritten(), 40u);
    EXPECT_EQ(inner.finishes, 1);
    sink.finish(); // idempotent, as every sink's
    EXPECT_EQ(inner.finishes, 1);
}

// A write that fails reaches the caller (from a later writeFrame() or from finish()), names its
// frame and stops the writes after it. Defect caught as well: the output of a failed write
// finalised by finish() (under its final name, a shorter clip) instead of left to abandon().
TEST(BackgroundSink, AFailedWriteReachesTheCallerAndStopsTheWrites)
{
    auto recording = std::make_unique<RecordingSink>(2);
    RecordingSink& inner = *recording;
    inner.hold = true;
    BackgroundSink sink(std::move(recording), 4);
    // Frames 3 and 4 are queued behind the failing frame 2 when it fails.
    for (int i = 0; i < 5; ++i)
        sink.write(pixel(i));
    release(inner);
    int thrown = 0;
    for (int i = 5; i < 10; ++i) {
        try {
            sink.write(pixel(i));
        } catch (const SinkError&) {
            ++thrown;
        }
    }
    try {
        sink.finish();
    } catch (const SinkError&) {
        ++thrown;
    }
    EXPECT_EQ(thrown, 1);
    EXPECT_EQ(inner.values, (std::vector<int>{0, 1}));
    EXPECT_EQ(sink.failedFrame(), 2u);
    EXPECT_EQ(sink.framesWritten(), 2u);
    EXPECT_EQ(inner.finishes, 0);
    EXPECT_EQ(sink.abandon(true), std::filesystem::path("kept"));
    EXPECT_EQ(inner.abandons, 1);
    sink.abandon(false); // once only
    EXPECT_EQ(inner.abandons, 1);
    EXPECT_EQ(inner.finishes, 0);
}

// A slow output holds the caller back once `depth` frames wait (frames are not queued without
// bound, each as large as the image).
TEST(BackgroundSink, TheCallerWaitsOnceItsDepthOfFramesIsQueued)
{
    auto recording = std::make_unique<RecordingSink>();
    RecordingSink& inner = *recording;
    inner.hold = true;
    BackgroundSink sink(std::move(recording), 2);
    std::atomic<int> given{0};
    std::thread writer([&] {
        for (int i = 0; i < 6; ++i) {
            sink.write(pixel(i));
            ++given;
        }
    });
    // One taken by the writing thread (held), two queued; the fourth call waits (given time to
    // come back if it did not).
    for (int i = 0; i < 500 && given.load() < 3; ++i)
        std::this_thread::sleep_for(10ms);
    std::this_thread::sleep_for(150ms);
    EXPECT_EQ(given.load(), 3);
    release(inner);
    writer.join();
    sink.finish();
    EXPECT_EQ(inner.values, (std::vector<int>{0, 1, 2, 3, 4, 5}));
}

} // namespace
} // namespace defocus
