// SPDX-License-Identifier: LGPL-2.1-or-later
// A sink written on a thread of its own: while the filter works on the next frame, the last ones
// are encoded and written (PNG encoding is single-threaded; at 1920x1080 a frame takes 50 ms).
// Frames are written in the order given, all of them before finish() finalises the output.
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
#include <utility>

#include "sinks/FrameSink.hpp"

namespace defocus {

class BackgroundSink final : public FrameSink {
public:
    /// Writes to `sink` (a file output; not a window or a virtual camera, whose frames are due
    /// when they are made) on its own thread, at most `depth` frames behind writeFrame() (>= 1).
    explicit BackgroundSink(std::unique_ptr<FrameSink> sink, std::size_t depth = 2);
    /// Without finish(), abandon(false), errors swallowed.
    ~BackgroundSink() override;
    BackgroundSink(const BackgroundSink&) = delete;
    BackgroundSink& operator=(const BackgroundSink&) = delete;

    SinkEncoding encoding() const override { return encoding_; }
    /// Queues the frame (waiting while `depth` are queued) and returns. Rethrows the error of a
    /// write that failed since the last call; once one has failed, nothing more is written.
    void write(const cv::Mat& image) override;
    void writeFrame(const cv::Mat& image, const Frame& origin) override;
    /// Writes what is queued, then finalises the output. After a failed write it rethrows that
    /// write's error (if not rethrown yet) and leaves the output to abandon(), unfinished; so it
    /// does when finalising fails.
    void finish() override;
    /// Writes what is queued (with `keep`; else drops it), then abandons the output. Rethrows an
    /// error of abandoning, not a write's (the caller that abandons has one of its own).
    std::filesystem::path abandon(bool keep) override;
    /// Frames written (not queued) so far.
    std::size_t framesWritten() const override;
    /// The output's description, as of the last frame written.
    std::string describe() const override;
    /// The position (0 = the first frame given) of the frame whose write failed, if one did.
    std::optional<std::size_t> failedFrame() const;

private:
    struct Job {
        cv::Mat image;
        std::optional<Frame> origin;
    };
    void enqueue(Job job);
    void run();
    /// Stops the thread once what is queued is written (`drop`: skipped); false if already done.
    bool stop(bool drop);

    std::unique_ptr<FrameSink> sink_;
    const std::size_t depth_;
    const SinkEncoding encoding_;
    mutable std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<Job> jobs_;
    std::size_t written_ = 0; // frames written
    std::size_t handed_ = 0;  // frames the sink took (a sink may write them later)
    std::string describe_;
    std::exception_ptr error_; // the failed write's, until rethrown
    std::optional<std::size_t> failedFrame_;
    bool stopping_ = false;
    bool finished_ = false; // the thread is stopped (or stopping)
    bool closed_ = false;   // sink_ finished or abandoned; the caller's thread only
    std::thread thread_; // last: starts once everything above is made
};

} // namespace defocus
