// SPDX-License-Identifier: LGPL-2.1-or-later
// BackgroundSink: one writing thread, a bounded queue of frames, the first error kept for the
// caller.
#include "sinks/BackgroundSink.hpp"

#include <fmt/format.h>

namespace defocus {

namespace fs = std::filesystem;

BackgroundSink::BackgroundSink(std::unique_ptr<FrameSink> sink, std::size_t depth)
    : sink_(std::move(sink)),
      depth_(depth == 0 ? 1 : depth),
      encoding_(sink_->encoding()),
      describe_(sink_->describe()),
      thread_([this] { run(); })
{
}

BackgroundSink::~BackgroundSink()
{
    try {
        abandon(false);
    } catch (...) {
        // A sink that was not finished is a failed run's, whose error the caller has.
    }
}

void BackgroundSink::run()
{
    std::unique_lock lock(mutex_);
    for (;;) {
        changed_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
        if (jobs_.empty())
            return; // stopping, and all written
        Job job = std::move(jobs_.front());
        jobs_.pop_front();
        const bool failed = failedFrame_.has_value();
        lock.unlock();
        changed_.notify_all(); // room in the queue
        std::exception_ptr error;
        std::string described;
        if (!failed) {
            try {
                if (job.origin)
                    sink_->writeFrame(job.image, *job.origin);
                else
                    sink_->write(job.image);
                described = sink_->describe();
            } catch (...) {
                error = std::current_exception();
            }
        }
        // A sink that encodes frames side by side counts them once written, and names the
        // frame whose write failed by the frames written before it.
        const std::size_t written = failed ? 0 : sink_->framesWritten();
        lock.lock();
        if (error) {
            error_ = error;
            failedFrame_ = written;
            written_ = written;
        } else if (!failed) {
            ++handed_;
            written_ = written;
            describe_ = std::move(described);
        }
        changed_.notify_all();
    }
}

void BackgroundSink::enqueue(Job job)
{
    std::unique_lock lock(mutex_);
    if (finished_)
        throw SinkError(fmt::format("{}: written after finish()", describe_));
    changed_.wait(lock, [&] { return jobs_.size() < depth_ || error_; });
    if (error_)
        std::rethrow_exception(std::exchange(error_, nullptr));
    if (failedFrame_)
        return; // failed before, and the caller was told: nothing more is written
    jobs_.push_back(std::move(job));
    lock.unlock();
    changed_.notify_all();
}

void BackgroundSink::write(const cv::Mat& image)
{
    enqueue({image, std::nullopt});
}

void BackgroundSink::writeFrame(const cv::Mat& image, const Frame& origin)
{
    enqueue({image, origin});
}

bool BackgroundSink::stop(bool drop)
{
    std::unique_lock lock(mutex_);
    if (finished_)
        return false;
    finished_ = true;
    stopping_ = true;
    if (drop)
        jobs_.clear();
    lock.unlock();
    changed_.notify_all();
    thread_.join(); // every queued frame written (or skipped after a failed one)
    return true;
}

fs::path BackgroundSink::abandon(bool keep)
{
    stop(!keep);
    if (std::exchange(closed_, true))
        return {};
    fs::path kept = sink_->abandon(keep);
    const std::lock_guard lock(mutex_);
    written_ = sink_->framesWritten();
    describe_ = sink_->describe();
    return kept;
}

void BackgroundSink::finish()
{
    stop(false);
    std::unique_lock lock(mutex_);
    // A failed write: the output is a failed run's, not finalised here; the caller abandons it
    // (as it would a sink written on its own thread), and gets the write's error, the first.
    if (closed_ || failedFrame_) {
        if (error_)
            std::rethrow_exception(std::exchange(error_, nullptr));
        return;
    }
    lock.unlock();
    try {
        sink_->finish();
    } catch (...) {
        // Left to abandon(): a sink that encodes frames side by side finds a failed write here.
        const std::lock_guard relock(mutex_);
        written_ = sink_->framesWritten();
        if (written_ < handed_)
            failedFrame_ = written_;
        throw;
    }
    closed_ = true;
    lock.lock();
    written_ = sink_->framesWritten();
    describe_ = sink_->describe();
}

std::size_t BackgroundSink::framesWritten() const
{
    const std::lock_guard lock(mutex_);
    return written_;
}

std::string BackgroundSink::describe() const
{
    const std::lock_guard lock(mutex_);
    return describe_;
}

std::optional<std::size_t> BackgroundSink::failedFrame() const
{
    const std::lock_guard lock(mutex_);
    return failedFrame_;
}

} // namespace defocus
