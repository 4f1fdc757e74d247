// SPDX-License-Identifier: LGPL-2.1-or-later
// A recorded source read ahead on threads of its own: while the filter works on one frame, the
// next ones are decoded (PNG decoding is single-threaded; at 1920x1080 a colour and a depth
// frame take 70 ms), several at a time where the source can hand its frames out as reads
// (FrameSource::nextRead()). Frames and the source's error come out in the order the source
// gives them.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "sources/FrameSource.hpp"

namespace defocus {

class ReadAheadSource final : public FrameSource {
public:
    /// Starts reading `source` (recorded, not live: a camera's frames are not to be queued) at
    /// once on `threads` threads (>= 1), at most `depth` frames ahead of what next() has taken
    /// (>= 1; at least `threads`).
    explicit ReadAheadSource(std::unique_ptr<FrameSource> source, std::size_t depth = 2, std::size_t threads = 1);
    /// Stops the reading threads (after the frames they are reading).
    ~ReadAheadSource() override;
    ReadAheadSource(const ReadAheadSource&) = delete;
    ReadAheadSource& operator=(const ReadAheadSource&) = delete;

    /// The next frame, waiting for it; nullopt at the end. Rethrows the source's error once the
    /// frames before it have been taken; after it, nullopt.
    std::optional<Frame> next() override;
    // Asked of the source before the threads start: a source need not answer them while it reads.
    std::optional<std::size_t> frameCount() const override { return frameCount_; }
    double frameRate() const override { return frameRate_; }
    std::string describe() const override { return describe_; }

    /// `source` read on `threads` threads (>= 1), one frame more than threads ahead: every thread
    /// busy while the caller takes a frame. What the programs and the library's Source use.
    static std::unique_ptr<ReadAheadSource> onThreads(std::unique_ptr<FrameSource> source, std::size_t threads);

    /// Threads for decoding a recorded clip ahead of the filter, where `clips` clips run at once:
    /// the CPUs this process may run on (its affinity: a Slurm job's or taskset's, not the
    /// machine's) less one for the caller, shared among the clips, at most 8, at least one.
    static std::size_t defaultThreads(std::size_t clips = 1);
    /// The CPUs this process may run on: its affinity's count (hardware_concurrency() where the
    /// affinity cannot be read).
    static std::size_t usableCpus();

private:
    /// One frame's place in the stream: read or not yet, its frame, or the error, or the end.
    struct Slot {
        bool done = false;
        std::optional<Frame> frame; ///< nullopt with no error: the end of the stream
        std::exception_ptr error;
    };
    void read();

    std::unique_ptr<FrameSource> source_;
    const std::size_t depth_;
    const std::optional<std::size_t> frameCount_;
    const double frameRate_;
    const std::string describe_;
    std::mutex sourceMutex_;    // one thread at a time asks the source for its next read
    std::mutex mutex_;          // the slots and flags below
    std::condition_variable changed_;
    std::deque<Slot> slots_;    // from the next to take, in stream order
    bool dispatchEnded_ = false; // the source said the end, or failed: no more slots
    bool failed_ = false;       // next() has rethrown the error: nothing more comes out
    bool stopping_ = false;
    std::vector<std::thread> threads_; // last: start once everything above is made
};

} // namespace defocus
