// SPDX-License-Identifier: LGPL-2.1-or-later
// Video sink: chooses a FourCC per container with fallbacks, writes to a hidden temporary file and
// renames it into place when finished.
#include "sinks/VideoSink.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <system_error>
#include <string_view>
#include <utility>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <opencv2/videoio/registry.hpp>

#include "filter/Log.hpp"
#include "sources/PathNames.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

/// Size of the probe video written (and deleted) by the constructor.
const cv::Size probeSize{64, 48};

struct Codec {
    const char* name;   ///< --codec NAME
    const char* fourcc; ///< what cv::VideoWriter is asked for
};

// avc1 is H.264 through FFmpeg's libx264 (Debian's FFmpeg has it); FFV1 is FFmpeg's lossless
// intra codec; VP90 is libvpx's VP9. For WebM, OpenCV's FFmpeg wrapper prints that the tag "is not
// supported with codec id 167" and writes VP9 all the same; no FourCC avoids it (WebM's muxer
// lists VP9 under tag 0), so withoutTagNotice drops that line.
const std::vector<Codec> kCodecs{{"h264", "avc1"}, {"mp4v", "mp4v"}, {"ffv1", "FFV1"}, {"vp9", "VP90"}, {"mjpg", "MJPG"}};

// The container's default first, then what it falls back to when that encoder is missing.
std::vector<std::string> defaultCodecsFor(const std::string& ext)
{
    if (ext == ".mp4")
        return {"h264", "mp4v"};
    if (ext == ".mkv")
        return {"ffv1"};
    if (ext == ".webm")
        return {"vp9"};
    if (ext == ".avi")
        return {"mjpg"};
    return {};
}

const Codec* findCodec(const std::string& name)
{
    for (const Codec& codec : kCodecs)
        if (name == codec.name)
            return &codec;
    return nullptr;
}

std::string joined(const std::vector<std::string>& items)
{
    std::string out;
    for (const std::string& item : items)
        out += (out.empty() ? "" : ", ") + item;
    return out;
}

/// The line OpenCV's FFmpeg wrapper writes with fprintf(stderr) when a container lists the codec
/// under another tag than the FourCC asked for; it goes on with the container's tag.
bool isTagNotice(const char* line)
{
    return std::strncmp(line, "OpenCV: FFMPEG: tag 0x", 22) == 0 && std::strstr(line, "is not supported with codec id");
}

/// A line of FFmpeg's log ("[mp4 @ 0x55d0...] Could not find tag for codec ffv1 ...") or of
/// OpenCV's ("[ WARN:0@0.1] ...", "OpenCV: FFMPEG: ...").
bool isLibraryLine(const char* line)
{
    return line[0] == '[' || std::strncmp(line, "OpenCV:", 7) == 0;
}

/// Runs `open` with file descriptor 2 sent to a temporary file, then copies what was caught to
/// standard error but OpenCV's tag notice (isTagNotice), so that a clean run prints only the
/// program's own lines; with `quiet`, the libraries' lines (isLibraryLine) go to the debug log.
/// What other threads write to standard error meanwhile is passed on late, not lost. Without a
/// temporary file or a spare descriptor it just runs `open`.
template <class Open>
bool withoutTagNotice(Open&& open, bool quiet)
{
    static std::mutex mutex; // one redirection at a time (--batch --in-flight opens in threads)
    const std::lock_guard lock(mutex);
    std::fflush(stderr);
    std::FILE* caught = std::tmpfile();
    const int saved = caught ? ::dup(STDERR_FILENO) : -1;
    if (saved < 0 || ::dup2(::fileno(caught), STDERR_FILENO) < 0) {
        if (saved >= 0)
            ::close(saved);
        if (caught)
            std::fclose(caught);
        return open();
    }
    struct Restore {
        int saved;
        std::FILE* caught;
        bool quiet;
        ~Restore()
        {
            std::fflush(stderr);
            ::dup2(saved, STDERR_FILENO);
            ::close(saved);
            std::rewind(caught);
            char line[4096];
            while (std::fgets(line, sizeof line, caught)) {
                if (quiet && isLibraryLine(line))
                    logger().debug("{}", std::string_view(line).substr(0, std::strcspn(line, "\n")));
                else if (!isTagNotice(line))
                    std::fputs(line, stderr);
            }
            std::fclose(caught);
        }
    } restore{saved, caught, quiet};
    return open();
}

} // namespace

VideoSink::VideoSink(fs::path file, double fps, const std::string& codec) : file_(std::move(file)), fps_(fps)
{
    const std::string ext = lowerExtension(file_);
    std::vector<std::string> codecs = defaultCodecsFor(ext);
    if (codecs.empty())
        throw SinkError(fmt::format("cannot write video '{}': unsupported container '{}' (use "
                                    ".mp4, .mkv, .webm or .avi)",
                                    file_.string(), ext));
    if (!codec.empty()) {
        if (!findCodec(codec))
            throw SinkError(fmt::format("cannot write video '{}': unknown codec '{}' (use h264, mp4v, ffv1, vp9 "
                                        "or mjpg)",
                                        file_.string(), codec));
        codecs = {codec};
    }
    if (!(fps_ > 0.0) || !std::isfinite(fps_))
        throw SinkError(fmt::format("cannot write video '{}': the frame rate must be positive, "
                                    "got {}",
                                    file_.string(), fps_));
    partial_ = temporaryPath(file_);

    std::error_code ec;
    const fs::path dir = file_.parent_path().empty() ? fs::path(".") : file_.parent_path();
    fs::create_directories(dir, ec);
    const fs::path probe = dir / fmt::format(".defocus-write-test-{}", ::getpid());
    const bool writable = std::ofstream(probe).good();
    fs::remove(probe, ec);
    if (!writable)
        throw SinkError(fmt::format("cannot write video '{}': folder '{}' is not writable",
                                    file_.string(), dir.string()));

    for (const std::string& candidate : codecs) {
        const std::string fourcc = findCodec(candidate)->fourcc;
        cv::VideoWriter writer;
        const bool opened = openWriter(writer, fourcc, probeSize, true);
        writer.release();
        fs::remove(partial_, ec);
        if (opened) {
            codec_ = fourcc;
            codecName_ = candidate;
            break;
        }
        logger().debug("video '{}': codec {} ({}) does not open here", file_.string(), candidate, fourcc);
    }
    if (codec_.empty())
        throw SinkError(fmt::format("cannot write video '{}': no encoder opens for codec {} in a {} file "
                                    "(OpenCV's FFmpeg lacks it, or the container cannot hold it)",
                                    file_.string(), joined(codecs), ext));
    if (codecName_ != codecs.front())
        logger().warn("video '{}': codec {} unavailable, using {}", file_.string(), codecs.front(), codecName_);
}

VideoSink::~VideoSink()
{
    try {
        abandon(false);
    } catch (const std::exception& e) {
        logger().error("{}", e.what());
    }
}

bool VideoSink::openWriter(cv::VideoWriter& writer, const std::string& fourcc, cv::Size size, bool probe) const
{
    // FFmpeg directly: with CAP_ANY a failed open falls through to GStreamer, which only adds
    // noise to the log.
    const int api = cv::videoio_registry::hasBackend(cv::CAP_FFMPEG) ? cv::CAP_FFMPEG : cv::CAP_ANY;
    try {
        return withoutTagNotice([&] {
            return writer.open(partial_.string(), api,
                               cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]), fps_, size, true);
        }, probe);
    } catch (const cv::Exception& e) {
        logger().debug("video '{}': {} failed to open: {}", file_.string(), fourcc, e.err);
        return false;
    }
}

void VideoSink::write(const cv::Mat& image)
{
    if (finished_)
        throw SinkError(fmt::format("cannot write video '{}': already finished", file_.string()));
    if (image.empty() || image.type() != CV_8UC3)
        throw SinkError(fmt::format("cannot write video '{}': expected a non-empty CV_8UC3 frame, "
                                    "got {} {}x{}",
                                    file_.string(), cv::typeToString(image.type()), image.cols,
                                    image.rows));
    if (!writer_.isOpened()) {
        if (!openWriter(writer_, codec_, image.size()))
            throw SinkError(fmt::format("cannot write video '{}': codec {} does not open at "
                                        "{}x{}",
                                        file_.string(), codec_, image.cols, image.rows));
        size_ = image.size();
        if (size_.width % 2 != 0 || size_.height % 2 != 0)
            logger().warn("video '{}': frames are {}x{}; codecs with 4:2:0 chroma store {}x{}",
                         file_.string(), size_.width, size_.height, size_.width & ~1,
                         size_.height & ~1);
    } else if (image.size() != size_) {
        throw SinkError(fmt::format("cannot write video '{}': frame {} is {}x{} but the video is "
                                    "{}x{}",
                                    file_.string(), written_, image.cols, image.rows, size_.width,
                                    size_.height));
    }
    writer_.write(image);
    ++written_;
}

void VideoSink::finish()
{
    if (finished_)
        return;
    finished_ = true;
    writer_.release();
    std::error_code ec;
    if (written_ == 0) {
        fs::remove(partial_, ec);
        logger().warn("video '{}': no frames written, so no file created", file_.string());
        return;
    }
    fs::rename(partial_, file_, ec);
    if (ec) {
        const std::string why = ec.message();
        fs::remove(partial_, ec);
        throw SinkError(fmt::format("cannot write video '{}': renaming '{}' failed: {}", file_.string(),
                                    partial_.string(), why));
    }
}

fs::path VideoSink::abandon(bool keep)
{
    if (finished_)
        return {};
    finished_ = true;
    writer_.release();
    return keepOrRemove(partial_, file_, false, keep, written_, "video");
}

std::string VideoSink::describe() const
{
    return fmt::format("video '{}' ({} ({}), {:g} fps, {} frames)", file_.string(), codecName_, codec_, fps_,
                       written_);
}

} // namespace defocus
