// SPDX-License-Identifier: LGPL-2.1-or-later
// Frame feed (newest-frame capture thread for live sources), pacing and statistics of the preview.
#include "samples/LiveLoop.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

namespace defocus {

std::optional<LiveClock::time_point> captureTime(double timestamp, LiveClock::time_point now)
{
    if (!(timestamp > 0.0) || !std::isfinite(timestamp))
        return std::nullopt;
    const auto at = LiveClock::time_point(
        std::chrono::duration_cast<LiveClock::duration>(std::chrono::duration<double>(timestamp)));
    if (at > now + std::chrono::milliseconds(1) || at < now - std::chrono::seconds(2))
        return std::nullopt;
    return at;
}

FrameFeed::FrameFeed(FrameSource& source, bool live) : source_(source), live_(live)
{
    if (live_)
        thread_ = std::thread([this] { capture(); });
}

FrameFeed::~FrameFeed()
{
    stop();
}

void FrameFeed::stop()
{
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    ready_.notify_all();
    if (thread_.joinable())
        thread_.join();
}

void FrameFeed::capture()
{
    for (;;) {
        {
            std::lock_guard lock(mutex_);
            if (stopping_)
                return;
        }
        std::optional<FedFrame> fed;
        try {
            std::optional<Frame> frame = source_.next();
            if (frame) {
                const auto now = LiveClock::now();
                const auto captured = captureTime(frame->timestampS, now);
                fed = FedFrame{std::move(*frame), captured.value_or(now), captured.has_value()};
            }
        } catch (...) {
            std::lock_guard lock(mutex_);
            error_ = std::current_exception();
            ended_ = true;
            ready_.notify_all();
            return;
        }
        std::lock_guard lock(mutex_);
        if (!fed) {
            ended_ = true;
            ready_.notify_all();
            return;
        }
        ++captured_;
        if (slot_ && !paused_)
            ++dropped_; // the consumer is slower than the camera: the older frame goes
        slot_ = std::move(fed);
        ready_.notify_all();
    }
}

std::optional<FedFrame> FrameFeed::next(std::chrono::milliseconds timeout)
{
    if (!live_) {
        std::lock_guard lock(mutex_);
        if (ended_) {
            if (error_)
                std::rethrow_exception(std::exchange(error_, nullptr));
            return std::nullopt;
        }
        std::optional<Frame> frame;
        try {
            frame = source_.next();
        } catch (...) {
            ended_ = true;
            throw;
        }
        if (!frame) {
            ended_ = true;
            return std::nullopt;
        }
        ++captured_;
        const auto now = LiveClock::now();
        return FedFrame{std::move(*frame), now, false};
    }
    std::unique_lock lock(mutex_);
    ready_.wait_for(lock, timeout, [this] { return slot_.has_value() || ended_; });
    if (slot_)
        return std::exchange(slot_, std::nullopt);
    if (error_)
        std::rethrow_exception(std::exchange(error_, nullptr));
    return std::nullopt;
}

void FrameFeed::setPaused(bool paused)
{
    std::lock_guard lock(mutex_);
    paused_ = paused;
}

bool FrameFeed::ended() const
{
    std::lock_guard lock(mutex_);
    return ended_ && !slot_ && !error_;
}

std::size_t FrameFeed::dropped() const
{
    std::lock_guard lock(mutex_);
    return dropped_;
}

std::size_t FrameFeed::captured() const
{
    std::lock_guard lock(mutex_);
    return captured_;
}

LiveClock::time_point Pacer::wait(double timestamp)
{
    double interval = fallbackS_;
    if (lastTimestamp_ > 0.0 && timestamp > lastTimestamp_ && timestamp - lastTimestamp_ <= 1.0)
        interval = timestamp - lastTimestamp_;
    LiveClock::time_point due = LiveClock::now();
    if (lastTaken_) {
        due = *lastTaken_ + std::chrono::duration_cast<LiveClock::duration>(std::chrono::duration<double>(interval));
        std::this_thread::sleep_until(due);
    }
    lastTaken_ = LiveClock::now();
    lastTimestamp_ = timestamp;
    return due;
}

void LiveStats::frameShown(LiveClock::time_point origin, LiveClock::time_point shown)
{
    latencyMs_.push_back(std::chrono::duration<double, std::milli>(shown - origin).count());
    if (!first_)
        first_ = shown;
    last_ = shown;
    recent_.push_back(shown);
    while (recent_.size() > 120)
        recent_.pop_front();
}

double LiveStats::recentFps(std::size_t window) const
{
    const std::size_t n = std::min(window, recent_.size());
    if (n < 2)
        return 0.0;
    const double seconds = std::chrono::duration<double>(recent_.back() - recent_[recent_.size() - n]).count();
    return seconds > 0.0 ? static_cast<double>(n - 1) / seconds : 0.0;
}

double LiveStats::recentLatencyMs(std::size_t window) const
{
    const std::size_t n = std::min(window, latencyMs_.size());
    if (n == 0)
        return 0.0;
    return std::accumulate(latencyMs_.end() - static_cast<std::ptrdiff_t>(n), latencyMs_.end(), 0.0) /
           static_cast<double>(n);
}

double LiveStats::fps() const
{
    if (latencyMs_.size() < 2)
        return 0.0;
    const double seconds = std::chrono::duration<double>(*last_ - *first_).count();
    return seconds > 0.0 ? static_cast<double>(latencyMs_.size() - 1) / seconds : 0.0;
}

double LiveStats::latencyPercentileMs(double q) const
{
    if (latencyMs_.empty())
        return 0.0;
    std::vector<double> sorted = latencyMs_;
    std::sort(sorted.begin(), sorted.end());
    const double at = std::clamp(q, 0.0, 1.0) * static_cast<double>(sorted.size() - 1);
    return sorted[static_cast<std::size_t>(std::lround(at))];
}

} // namespace defocus
