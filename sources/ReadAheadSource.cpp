// SPDX-License-Identifier: LGPL-2.1-or-later
// ReadAheadSource: one reading thread, a bounded queue of frames, the error after them.
#include "sources/ReadAheadSource.hpp"

#include <utility>

namespace defocus {

ReadAheadSource::ReadAheadSource(std::unique_ptr<FrameSource> source, std::size_t depth)
    : source_(std::move(source)),
      depth_(depth == 0 ? 1 : depth),
      frameCount_(source_->frameCount()),
      frameRate_(source_->frameRate()),
      describe_(source_->describe()),
      thread_([this] { read(); })
{
}

ReadAheadSource::~ReadAheadSource()
{
    {
        const std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
}

void ReadAheadSource::read()
{
    for (;;) {
        {
            std::unique_lock lock(mutex_);
            changed_.wait(lock, [&] { return stopping_ || frames_.size() < depth_; });
            if (stopping_)
                return;
        }
        std::optional<Frame> frame;
        std::exception_ptr error;
        try {
            frame = source_->next();
        } catch (...) {
            error = std::current_exception();
        }
        {
            const std::lock_guard lock(mutex_);
            if (frame)
                frames_.push_back(std::move(*frame));
            else
                ended_ = true;
            error_ = error;
        }
        changed_.notify_all();
        if (!frame)
            return;
    }
}

std::optional<Frame> ReadAheadSource::next()
{
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !frames_.empty() || ended_; });
    if (!frames_.empty()) {
        Frame frame = std::move(frames_.front());
        frames_.pop_front();
        lock.unlock();
        changed_.notify_all();
        return frame;
    }
    if (error_)
        std::rethrow_exception(std::exchange(error_, nullptr));
    return std::nullopt;
}

} // namespace defocus
