// SPDX-License-Identifier: LGPL-2.1-or-later
// Image outputs: a sequence in a folder laid out as a TUM RGB-D clip (PNG, or EXR when linear), or
// one image file that each frame replaces.   defocus in/ -o out/   defocus photo.png --depth d.png -o out.exr
// Both are written under a hidden temporary name beside the output (.out.partial/, .out.partial.png;
// out/.defocus.partial/ in a folder that exists) and put in place by finish(); abandon() leaves the
// output's name alone (FrameSink.hpp).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "sinks/FrameSink.hpp"

namespace defocus {

/// Writes a folder that is again a TUM RGB-D clip: each frame under its input's name (the TUM
/// timestamp, e.g. 1305031102.175304.png; frame_000042.png when the input has no file names),
/// its depth as a 16-bit PNG at 5000 units per metre in depth/, and rgb.txt, depth.txt and
/// associations.txt listing them (written when the sequence finishes). The frames go into the
/// hidden folder .NAME.partial beside `folder`, which finish() renames to `folder`; when `folder`
/// exists, into FOLDER/.defocus.partial, whose files finish() moves into it.
/// Frames are named in the order given; their files may be encoded side by side on threads of
/// the sink's own (PNG encoding is single-threaded: ~50 ms a 1920x1080 frame). Whatever the
/// threads, the files and lists are those of one frame after the other, and a write that fails
/// counts the frames before it as written and none after it.
class ImageSequenceSink final : public FrameSink {
public:
    /// Creates the temporary folder beside `folder` and checks that it is writable; throws
    /// SinkError if not. `linear`: EXR files from CV_32FC3 frames instead of PNG files from
    /// CV_8UC3. `fps` gives the timestamps of frames whose input has none (index / fps).
    /// `threads`: frames encoded at once. With 1, writeFrame() writes the frame before it
    /// returns; with more, it queues the frame's encoding and returns (waiting while `threads`
    /// frames are queued besides those being encoded), and the frame's image and depth are
    /// referenced until written: give each frame pixels of its own (as sources and the filter do).
    ImageSequenceSink(std::filesystem::path folder, bool linear, double fps = 30.0, std::size_t threads = 1);
    /// Without finish(), abandons the frames (abandon(false)).
    ~ImageSequenceSink() override;
    ImageSequenceSink(const ImageSequenceSink&) = delete;
    ImageSequenceSink& operator=(const ImageSequenceSink&) = delete;

    SinkEncoding encoding() const override;
    /// A frame with no input behind it: frame_NNNNNN, timestamp index / fps, no depth.
    void write(const cv::Mat& image) override;
    /// Throws SinkError for a frame of the wrong type, and the error of the first frame whose
    /// write failed (this one's, or one queued before); the error comes once the frames before
    /// the failed one are written, so framesWritten() is then that frame's position. After a
    /// failed write every call throws its error again.
    void writeFrame(const cv::Mat& image, const Frame& origin) override;
    /// Waits for the frames queued, writes the lists and renames the temporary folder to the
    /// output folder. Into a folder that exists (empty, or holding files with -y), the frames,
    /// then the lists, are moved in one by one; its other files stay. With no frame written,
    /// nothing is created (with a warning). After a failed write it throws that write's error
    /// and leaves the output unfinished, for abandon().
    void finish() override;
    /// Removes the temporary folder, or with `keep` writes the frames queued, lists the frames
    /// written before any failed one (removing files written after it) and renames the folder
    /// NAME.partial (replacing an earlier one).
    std::filesystem::path abandon(bool keep) override;
    /// Frames written one after the other from the first: a frame whose files are written while
    /// one before it is still being encoded counts once that one is written.
    std::size_t framesWritten() const override;
    std::string describe() const override;
    /// Frames encoded at once.
    std::size_t threads() const { return threads_.empty() ? 1 : threads_.size(); }

private:
    struct Entry {
        double timestamp;
        std::string color; ///< relative to the folder, e.g. "1305031102.175304.png"
        std::string depth; ///< e.g. "depth/1305031102.175304.png"; empty without depth
    };
    /// One frame's files to encode and write.
    struct Job {
        std::size_t position; ///< in entries_
        cv::Mat image;
        Frame depth; ///< the input's depth and depthScale only
        std::filesystem::path colorFile, depthFile;
    };
    std::string nameFor(const Frame& origin);
    void writeLists() const;
    static void encode(const Job& job);
    void encodeOnThread();
    /// Records job `position` as written (no `error`) or failed; the lock is held.
    void recordLocked(std::size_t position, std::exception_ptr error);
    /// Waits until no frame is queued or being encoded.
    void settle(std::unique_lock<std::mutex>& lock);
    /// Settles and rethrows the first failed write's error, if one failed.
    void rethrowFailure(std::unique_lock<std::mutex>& lock);
    /// Stops the threads once what is queued is written (`drop`: skipped, with what comes after a
    /// failed write).
    void stopThreads(bool drop);

    std::filesystem::path folder_; ///< the output, without a trailing '/'
    std::filesystem::path work_;   ///< the hidden folder the frames go to until finish()
    bool linear_;
    double fps_;
    bool finished_ = false;
    std::vector<Entry> entries_;   ///< every frame named, in order (the caller's thread only)
    std::set<std::string> used_;
    bool depthFolder_ = false;     ///< depth/ made in work_

    mutable std::mutex mutex_;     // what follows, shared with the encoding threads
    std::condition_variable changed_;
    std::deque<Job> queue_;        ///< waiting to be encoded, in order
    std::size_t encoding_ = 0;     ///< being encoded now
    std::vector<bool> done_;       ///< per entry: its files are written
    std::size_t written_ = 0;      ///< entries written one after the other from the first
    std::optional<std::size_t> failedAt_; ///< the first entry whose write failed
    std::exception_ptr error_;     ///< its error
    bool stopping_ = false;
    std::size_t queueDepth_ = 0;   ///< frames queued besides those being encoded
    std::vector<std::thread> threads_; // last: start once everything above is made
};

/// Writes every frame to the same hidden temporary file beside `file`, replacing it atomically: the
/// last frame wins, and finish() renames it to `file`. .exr gets linear float, .png/.jpg/.jpeg
/// 8-bit sRGB.
class SingleImageSink final : public FrameSink {
public:
    /// Creates the parent folder if needed and checks that it is writable; throws SinkError for an
    /// unsupported extension or a folder that cannot be written.
    explicit SingleImageSink(std::filesystem::path file);
    /// Without finish(), abandons the image (abandon(false)).
    ~SingleImageSink() override;

    SinkEncoding encoding() const override { return encoding_; }
    void write(const cv::Mat& image) override;
    /// Renames the last frame to `file`; with no frame written, creates nothing.
    void finish() override;
    /// Removes the last frame, or with `keep` renames it NAME.partial.EXT.
    std::filesystem::path abandon(bool keep) override;
    std::size_t framesWritten() const override { return written_; }
    std::string describe() const override;

private:
    std::filesystem::path file_;
    std::filesystem::path work_; ///< the hidden file the frames go to until finish()
    SinkEncoding encoding_;
    std::size_t written_ = 0;
    bool finished_ = false;
};

/// imwrite to a hidden temporary name next to `file`, then rename over it; throws SinkError.
void writeImageAtomically(const std::filesystem::path& file, const cv::Mat& image);

} // namespace defocus
