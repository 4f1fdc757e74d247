// SPDX-License-Identifier: LGPL-2.1-or-later
// ReadAheadSource: reading threads that take the source's reads in stream order, one at a time,
// and run them side by side; slots in stream order hold what they give until next() takes it.
#include "sources/ReadAheadSource.hpp"

#include <algorithm>
#include <utility>

#include <sched.h>

namespace defocus {

ReadAheadSource::ReadAheadSource(std::unique_ptr<FrameSource> source, std::size_t depth, std::size_t threads)
    : source_(std::move(source)),
      depth_(std::max({depth, threads, std::size_t{1}})),
      frameCount_(source_->frameCount()),
      frameRate_(source_->frameRate()),
      describe_(source_->describe())
{
    for (std::size_t i = 0; i < std::max(threads, std::size_t{1}); ++i)
        threads_.emplace_back([this] { read(); });
}

ReadAheadSource::~ReadAheadSource()
{
    {
        const std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    for (std::thread& thread : threads_)
        thread.join();
}

std::unique_ptr<ReadAheadSource> ReadAheadSource::onThreads(std::unique_ptr<FrameSource> source, std::size_t threads)
{
    return std::make_unique<ReadAheadSource>(std::move(source), threads + 1, threads);
}

std::size_t ReadAheadSource::usableCpus()
{
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    if (sched_getaffinity(0, sizeof allowed, &allowed) == 0)
        return static_cast<std::size_t>(CPU_COUNT(&allowed));
    return std::max(std::thread::hardware_concurrency(), 1u);
}

std::size_t ReadAheadSource::defaultThreads(std::size_t clips)
{
    const std::size_t cpus = usableCpus();
    return std::clamp<std::size_t>((cpus > 1 ? cpus - 1 : 1) / std::max<std::size_t>(clips, 1), 1, 8);
}

void ReadAheadSource::read()
{
    for (;;) {
        // The source's next read and its slot, in stream order: one thread at a time.
        std::unique_lock sourceLock(sourceMutex_);
        Slot* slot = nullptr;
        {
            std::unique_lock lock(mutex_);
            changed_.wait(lock, [&] { return stopping_ || dispatchEnded_ || slots_.size() < depth_; });
            if (stopping_ || dispatchEnded_)
                return;
            slot = &slots_.emplace_back(); // a deque keeps its elements where they are on push and pop at the ends
        }
        std::optional<Read> work;
        std::exception_ptr error;
        try {
            work = source_->nextRead();
        } catch (...) {
            error = std::current_exception();
        }
        if (!work || error) {
            {
                const std::lock_guard lock(mutex_);
                slot->done = true;
                slot->error = error;
                dispatchEnded_ = true;
            }
            changed_.notify_all();
            return;
        }
        sourceLock.unlock();

        // The reading and decoding, beside the other threads'.
        std::optional<Frame> frame;
        try {
            frame = (*work)();
        } catch (...) {
            error = std::current_exception();
        }
        {
            const std::lock_guard lock(mutex_);
            slot->done = true;
            slot->frame = std::move(frame);
            slot->error = error;
            if (error || !slot->frame)
                dispatchEnded_ = true; // nothing after an error or an end is taken
        }
        changed_.notify_all();
    }
}

std::optional<Frame> ReadAheadSource::next()
{
    std::unique_lock lock(mutex_);
    if (failed_)
        return std::nullopt;
    changed_.wait(lock, [&] { return (!slots_.empty() && slots_.front().done) || (slots_.empty() && dispatchEnded_); });
    if (slots_.empty())
        return std::nullopt;
    Slot slot = std::move(slots_.front());
    slots_.pop_front();
    if (slot.error || !slot.frame) {
        // The error or the end: what was read after it is not given.
        failed_ = true;
        dispatchEnded_ = true;
    }
    lock.unlock();
    changed_.notify_all();
    if (slot.error)
        std::rethrow_exception(slot.error);
    return std::move(slot.frame);
}

} // namespace defocus
