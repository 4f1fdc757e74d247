// BackgroundSink: one writing thread, a bounded queue of frames, the first error kept for the
// caller.
#include "sinks/BackgroundSink.hpp"

#include <fmt/format.h>

namespace defocus {

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
        finish();
    } catch (...) {
        // The caller that wanted the error called finish() itself.
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
        lock.lock();
        if (error) {
            error_ = error;
            failedFrame_ = written_;
        } else if (!failed) {
            ++written_;
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

void BackgroundSink::finish()
{
    std::unique_lock lock(mutex_);
    if (finished_) {
        if (error_)
            std::rethrow_exception(std::exchange(error_, nullptr));
        return;
    }
    finished_ = true;
    stopping_ = true;
    lock.unlock();
    changed_.notify_all();
    thread_.join(); // every queued frame written (or skipped after a failed one)
    // Finalised even after a failed write, as a sink written on the caller's thread would be by
    // the caller's finish(); the write's error, the first, is the one rethrown.
    std::exception_ptr finishError;
    try {
        sink_->finish();
    } catch (...) {
        finishError = std::current_exception();
    }
    lock.lock();
    describe_ = sink_->describe();
    if (std::exception_ptr error = error_ ? std::exchange(error_, nullptr) : finishError)
        std::rethrow_exception(error);
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
