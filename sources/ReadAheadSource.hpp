// SPDX-License-Identifier: LGPL-2.1-or-later
// A recorded source read ahead on a thread of its own: while the filter works on one frame, the
// next ones are decoded (PNG decoding is single-threaded; at 1920x1080 a colour and a depth
// frame take 70 ms). Frames and the source's error come out in the order the source gives them.
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

#include "sources/FrameSource.hpp"

namespace defocus {

class ReadAheadSource final : public FrameSource {
public:
    /// Starts reading `source` (recorded, not live: a camera's frames are not to be queued) at
    /// once, at most `depth` frames ahead of what next() has taken (>= 1).
    explicit ReadAheadSource(std::unique_ptr<FrameSource> source, std::size_t depth = 2);
    /// Stops the reading thread (after the frame it is reading).
    ~ReadAheadSource() override;
    ReadAheadSource(const ReadAheadSource&) = delete;
    ReadAheadSource& operator=(const ReadAheadSource&) = delete;

    /// The next frame, waiting for it; nullopt at the end. Rethrows the source's error once the
    /// frames before it have been taken; after it, nullopt.
    std::optional<Frame> next() override;
    // Asked of the source before the thread starts: a source need not answer them while it reads.
    std::optional<std::size_t> frameCount() const override { return frameCount_; }
    double frameRate() const override { return frameRate_; }
    std::string describe() const override { return describe_; }

private:
    void read();

    std::unique_ptr<FrameSource> source_;
    const std::size_t depth_;
    const std::optional<std::size_t> frameCount_;
    const double frameRate_;
    const std::string describe_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<Frame> frames_;  // read, not yet taken
    std::exception_ptr error_;  // after the frames in frames_
    bool ended_ = false;        // the source ended or failed: nothing more comes after frames_
    bool stopping_ = false;
    std::thread thread_;        // last: starts once everything above is made
};

} // namespace defocus
