// SPDX-License-Identifier: LGPL-2.1-or-later
// Helpers of the preview loop: a frame feed that never blocks on live sources (a capture thread
// keeps only the newest frame and counts the ones it replaces), playback pacing for recorded
// clips, and latency/fps statistics.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "defocus/Frame.hpp"
#include "sources/FrameSource.hpp"

namespace defocus {

using LiveClock = std::chrono::steady_clock;

/// A frame and when its latency starts.
struct FedFrame {
    Frame frame;
    /// The capture time when the frame carries one on this machine's monotonic clock (V4L2
    /// timestamps, within the last 2 s), else when the source handed it over.
    LiveClock::time_point origin;
    bool fromCaptureClock = false;
};

/// The capture time `timestamp` (seconds) as a steady_clock time when it is believable on that
/// clock: steady_clock is CLOCK_MONOTONIC on Linux, as V4L2 timestamps are, and the time lies
/// within the last 2 s of `now`. nullopt otherwise (file timestamps, wall-clock times).
std::optional<LiveClock::time_point> captureTime(double timestamp, LiveClock::time_point now);

/// Frames from a source, two ways:
///  - recorded (isLive() false): next() reads the next frame on the caller's thread; nothing is
///    ever dropped, a slow consumer just plays slower;
///  - live: a capture thread reads continuously into a one-frame slot; a frame still in the slot
///    when the next arrives is replaced and counted as dropped, so the consumer always gets the
///    newest frame and the camera never waits for it.
class FrameFeed {
public:
    FrameFeed(FrameSource& source, bool live);
    ~FrameFeed();
    FrameFeed(const FrameFeed&) = delete;
    FrameFeed& operator=(const FrameFeed&) = delete;

    /// Recorded: the next frame, or nullopt at the end. Live: the newest frame not yet taken,
    /// waiting at most `timeout` for one; nullopt when none came or the stream ended. Rethrows
    /// the source's error (once the frames before it have been taken).
    std::optional<FedFrame> next(std::chrono::milliseconds timeout);
    /// Live: while paused, frames still replace each other in the slot (the camera keeps
    /// running) but are not counted as dropped: a paused preview is not a slow one.
    void setPaused(bool paused);
    /// No more frames will come.
    bool ended() const;
    bool live() const { return live_; }
    /// Live frames replaced in the slot before the consumer took them.
    std::size_t dropped() const;
    /// Frames read from the source.
    std::size_t captured() const;
    /// Stops the capture thread (it finishes the read in progress). Idempotent.
    void stop();

private:
    void capture();

    FrameSource& source_;
    const bool live_;
    mutable std::mutex mutex_;
    std::condition_variable ready_;
    std::optional<FedFrame> slot_;
    std::exception_ptr error_;
    bool ended_ = false;
    bool stopping_ = false;
    bool paused_ = false;
    std::size_t dropped_ = 0;
    std::size_t captured_ = 0;
    std::thread thread_;
};

/// Plays a recorded clip no faster than it was recorded: wait() returns when the frame with
/// `timestamp` is due, `interval` after the previous one was taken (the timestamp difference
/// when known and within (0, 1] s, else 1 / fps). A slow consumer is never made to catch up.
class Pacer {
public:
    explicit Pacer(double fallbackIntervalS) : fallbackS_(fallbackIntervalS) {}
    /// Sleeps until the frame stamped `timestamp` is due, records it as taken and returns when
    /// it was due (now for the first frame).
    LiveClock::time_point wait(double timestamp);

private:
    double fallbackS_;
    double lastTimestamp_ = 0.0;
    std::optional<LiveClock::time_point> lastTaken_;
};

/// Latency samples (milliseconds) and display times of new frames: fps over the last frames for
/// the HUD, and percentiles over the run for the summary.
class LiveStats {
public:
    void frameShown(LiveClock::time_point origin, LiveClock::time_point shown);
    /// New frames per second over the last `window` frames shown; 0 before two.
    double recentFps(std::size_t window = 30) const;
    /// Mean latency of the last `window` frames, ms.
    double recentLatencyMs(std::size_t window = 30) const;
    /// Frames per second over the whole run (first to last frame shown).
    double fps() const;
    /// Latency percentile over the run, q in [0, 1], ms; 0 when nothing was shown.
    double latencyPercentileMs(double q) const;
    std::size_t frames() const { return latencyMs_.size(); }

private:
    std::vector<double> latencyMs_;
    std::deque<LiveClock::time_point> recent_;
    std::optional<LiveClock::time_point> first_, last_;
};

} // namespace defocus
