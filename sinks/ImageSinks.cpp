// SPDX-License-Identifier: LGPL-2.1-or-later
// Image sinks: numbered PNG/EXR sequences and single image files, written under a hidden
// temporary name and renamed into place when the run is done.
#include "sinks/ImageSinks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <fstream>
#include <system_error>
#include <utility>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "filter/Log.hpp"
#include "sources/ImageIO.hpp"
#include "sources/PathNames.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

constexpr int jpegQuality = 95;

int expectedType(SinkEncoding encoding)
{
    return encoding == SinkEncoding::Linear32F ? CV_32FC3 : CV_8UC3;
}

void checkFrame(const cv::Mat& image, SinkEncoding encoding, const fs::path& target)
{
    if (image.empty() || image.type() != expectedType(encoding))
        throw SinkError(fmt::format("cannot write '{}': expected a non-empty {} frame, got {} {}x{}",
                                    target.string(), cv::typeToString(expectedType(encoding)),
                                    cv::typeToString(image.type()), image.cols, image.rows));
}

// Creates `folder` and proves it writable with a throw-away file, so that a bad output path
// fails before any frame is processed.
void prepareFolder(const fs::path& folder, const fs::path& output)
{
    std::error_code ec;
    const fs::path dir = folder.empty() ? fs::path(".") : folder;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir))
        throw SinkError(fmt::format("cannot create output '{}': folder '{}' cannot be created{}",
                                    output.string(), dir.string(),
                                    ec ? ": " + ec.message() : std::string()));
    const fs::path probe = dir / fmt::format(".defocus-write-test-{}", ::getpid());
    const bool writable = std::ofstream(probe).good();
    fs::remove(probe, ec);
    if (!writable)
        throw SinkError(fmt::format("cannot create output '{}': folder '{}' is not writable",
                                    output.string(), dir.string()));
}

std::vector<int> writeParams(const std::string& ext)
{
    if (ext == ".jpg" || ext == ".jpeg")
        return {cv::IMWRITE_JPEG_QUALITY, jpegQuality};
    if (ext == ".exr")
        return {cv::IMWRITE_EXR_TYPE, cv::IMWRITE_EXR_TYPE_FLOAT};
    return {};
}

} // namespace

// imwrite to ".NAME.partial.EXT" next to `file` (same file system, extension kept so OpenCV picks
// the same encoder), then rename over `file`: readers never see a half-written image.
void writeImageAtomically(const fs::path& file, const cv::Mat& image)
{
    const std::string ext = lowerExtension(file);
    if (ext == ".exr")
        enableOpenExr();
    const fs::path partial =
        file.parent_path() / fmt::format(".{}.partial{}", file.stem().string(), file.extension().string());
    bool written = false;
    std::string reason = "the encoder failed";
    try {
        written = cv::imwrite(partial.string(), image, writeParams(ext));
    } catch (const cv::Exception& e) {
        reason = e.err;
    }
    std::error_code ec;
    if (!written) {
        fs::remove(partial, ec);
        throw SinkError(fmt::format("cannot write '{}': {}", file.string(), reason));
    }
    fs::rename(partial, file, ec);
    if (ec) {
        fs::remove(partial, ec);
        throw SinkError(fmt::format("cannot write '{}': {}", file.string(), ec.message()));
    }
}

namespace {

bool isImageName(const fs::path& name)
{
    static const std::set<std::string> kImage{".png", ".jpg", ".jpeg", ".exr", ".tif", ".tiff", ".bmp", ".ppm", ".pgm"};
    return kImage.count(lowerExtension(name)) > 0 && !name.stem().empty();
}

constexpr double kTumUnitsPerMetre = 5000.0;

// Depth in metres as TUM stores it: 16-bit, 5000 units per metre, 0 = no measurement; depths past
// 13.1 m (the format's limit) are clamped to it. 16-bit depth read at 5000 units is written as it
// came.
cv::Mat tumDepth(const cv::Mat& metres)
{
    cv::Mat out(metres.size(), CV_16UC1);
    for (int y = 0; y < metres.rows; ++y)
        for (int x = 0; x < metres.cols; ++x) {
            const float d = metres.at<float>(y, x);
            const bool valid = std::isfinite(d) && d > 0.0f;
            out.at<std::uint16_t>(y, x) =
                valid ? static_cast<std::uint16_t>(std::min(65535.0f, std::round(d * static_cast<float>(kTumUnitsPerMetre)))) : std::uint16_t{0};
        }
    return out;
}

} // namespace

ImageSequenceSink::ImageSequenceSink(fs::path folder, bool linear, double fps, std::size_t threads)
    : folder_(folder.has_filename() ? std::move(folder) : folder.parent_path()), linear_(linear), fps_(fps > 0.0 ? fps : 30.0)
{
    // Beside a new folder, so that one rename puts it in place; inside one that exists (it may be
    // a mount point, or the current folder), so that its files can be moved in.
    std::error_code ec;
    work_ = fs::is_directory(folder_, ec) ? folder_ / ".defocus.partial" : temporaryPath(folder_, true);
    fs::remove_all(work_, ec); // what a killed run left under this output's temporary name
    prepareFolder(work_, folder_);
    if (linear_)
        enableOpenExr(); // sets the environment: before any thread encodes
    // One thread writes in the caller's call; more encode on threads of their own.
    if (threads > 1) {
        queueDepth_ = threads;
        for (std::size_t i = 0; i < threads; ++i)
            threads_.emplace_back([this] { encodeOnThread(); });
    }
}

ImageSequenceSink::~ImageSequenceSink()
{
    try {
        abandon(false);
    } catch (const std::exception& e) {
        logger().error("{}", e.what());
    }
    stopThreads(true); // where abandon() failed before it stopped them
}

SinkEncoding ImageSequenceSink::encoding() const
{
    return linear_ ? SinkEncoding::Linear32F : SinkEncoding::Srgb8;
}

std::string ImageSequenceSink::nameFor(const Frame& origin)
{
    const fs::path name(origin.name);
    std::string stem = isImageName(name) ? name.stem().string() : std::string();
    if (stem.empty() || used_.count(stem) > 0)
        stem = fmt::format("frame_{:06}", entries_.size());
    used_.insert(stem);
    return stem;
}

void ImageSequenceSink::write(const cv::Mat& image)
{
    Frame origin;
    origin.index = entries_.size();
    writeFrame(image, origin);
}

void ImageSequenceSink::encode(const Job& job)
{
    if (!job.depthFile.empty()) {
        const bool tumUnits = job.depth.depth.type() == CV_16UC1 && job.depth.depthScale == kTumUnitsPerMetre;
        writeImageAtomically(job.depthFile, tumUnits ? job.depth.depth : tumDepth(depthMetres(job.depth)));
    }
    writeImageAtomically(job.colorFile, job.image);
}

void ImageSequenceSink::recordLocked(std::size_t position, std::exception_ptr error)
{
    if (error) {
        if (!failedAt_ || position < *failedAt_) {
            failedAt_ = position;
            error_ = error;
        }
        return;
    }
    done_[position] = true;
    while (written_ < done_.size() && done_[written_])
        ++written_;
}

void ImageSequenceSink::encodeOnThread()
{
    std::unique_lock lock(mutex_);
    for (;;) {
        changed_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
        if (queue_.empty())
            return; // stopping, and all written
        Job job = std::move(queue_.front());
        queue_.pop_front();
        if (failedAt_ && job.position > *failedAt_)
            continue; // after a failed write: nothing more is written
        ++encoding_;
        lock.unlock();
        changed_.notify_all(); // room in the queue
        std::exception_ptr error;
        try {
            encode(job);
        } catch (...) {
            error = std::current_exception();
        }
        const std::size_t position = job.position;
        job = {}; // the frame's memory goes before the caller is told there is room
        lock.lock();
        --encoding_;
        recordLocked(position, error);
        changed_.notify_all();
    }
}

void ImageSequenceSink::settle(std::unique_lock<std::mutex>& lock)
{
    changed_.wait(lock, [&] { return queue_.empty() && encoding_ == 0; });
}

void ImageSequenceSink::rethrowFailure(std::unique_lock<std::mutex>& lock)
{
    if (!failedAt_)
        return;
    // The frames before the failed one are written (or failed first) before its error comes.
    settle(lock);
    std::rethrow_exception(error_);
}

void ImageSequenceSink::stopThreads(bool drop)
{
    {
        std::unique_lock lock(mutex_);
        if (threads_.empty() || stopping_)
            return;
        if (drop)
            queue_.clear();
        stopping_ = true;
    }
    changed_.notify_all();
    for (std::thread& thread : threads_)
        thread.join();
}

void ImageSequenceSink::writeFrame(const cv::Mat& image, const Frame& origin)
{
    std::unique_lock lock(mutex_);
    if (finished_)
        throw SinkError(fmt::format("cannot write sequence '{}': already finished", folder_.string()));
    rethrowFailure(lock);
    const std::size_t position = entries_.size();
    const double timestamp = origin.timestampS > 0.0 ? origin.timestampS : static_cast<double>(position) / fps_;
    const std::string stem = nameFor(origin);
    Entry entry{timestamp, stem + (linear_ ? ".exr" : ".png"), {}};
    try {
        checkFrame(image, encoding(), folder_ / entry.color);
    } catch (...) {
        settle(lock); // the frames before it are written when the caller hears of it
        used_.erase(stem);
        throw;
    }
    Job job{position, image, {}, work_ / entry.color, {}};
    if (!origin.depth.empty() && (origin.depth.type() == CV_32FC1 || origin.depth.type() == CV_16UC1)) {
        entry.depth = "depth/" + stem + ".png";
        if (!std::exchange(depthFolder_, true)) {
            std::error_code ec;
            fs::create_directories(work_ / "depth", ec);
        }
        job.depth.depth = origin.depth;
        job.depth.depthScale = origin.depthScale;
        job.depthFile = work_ / entry.depth;
    }
    entries_.push_back(std::move(entry));
    done_.push_back(false);
    if (threads_.empty()) {
        lock.unlock();
        std::exception_ptr error;
        try {
            encode(job);
        } catch (...) {
            error = std::current_exception();
        }
        lock.lock();
        recordLocked(position, error);
        rethrowFailure(lock);
        return;
    }
    changed_.wait(lock, [&] { return queue_.size() < queueDepth_ || failedAt_; });
    rethrowFailure(lock); // an earlier frame failed while this one waited: it is not written
    queue_.push_back(std::move(job));
    lock.unlock();
    changed_.notify_all();
}

std::size_t ImageSequenceSink::framesWritten() const
{
    const std::lock_guard lock(mutex_);
    return written_;
}

void ImageSequenceSink::writeLists() const
{
    // The frames written one after the other: none after a failed one.
    const std::vector<Entry> entries(entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(written_));
    const auto list = [&](const char* what, auto line) {
        std::string text = fmt::format("# {}\n# file: written by defocus\n# timestamp {}\n", what,
                                       std::string(what) == "associations" ? "rgb timestamp depth" : "filename");
        for (const Entry& e : entries)
            if (const std::string l = line(e); !l.empty())
                text += l + "\n";
        return text;
    };
    writeFileAtomically(work_ / "rgb.txt",
                        list("color images", [](const Entry& e) { return fmt::format("{:.6f} {}", e.timestamp, e.color); }));
    const bool anyDepth = std::any_of(entries.begin(), entries.end(), [](const Entry& e) { return !e.depth.empty(); });
    if (!anyDepth)
        return;
    writeFileAtomically(work_ / "depth.txt", list("depth maps", [](const Entry& e) {
                            return e.depth.empty() ? std::string() : fmt::format("{:.6f} {}", e.timestamp, e.depth);
                        }));
    writeFileAtomically(work_ / "associations.txt", list("associations", [](const Entry& e) {
                            return e.depth.empty() ? std::string()
                                                   : fmt::format("{:.6f} {} {:.6f} {}", e.timestamp, e.color,
                                                                 e.timestamp, e.depth);
                        }));
}

void ImageSequenceSink::finish()
{
    if (finished_)
        return;
    {
        std::unique_lock lock(mutex_);
        settle(lock);
        rethrowFailure(lock); // unfinished: the caller abandons it
    }
    stopThreads(false);
    finished_ = true;
    std::error_code ec;
    if (written_ == 0) {
        fs::remove_all(work_, ec);
        logger().warn("sequence '{}': no frames written, so nothing written there", folder_.string());
        return;
    }
    writeLists();
    const auto failed = [&](const fs::path& what) {
        return SinkError(fmt::format("cannot write sequence '{}': moving '{}' into place failed: {}", folder_.string(),
                                     what.string(), ec.message()));
    };
    // A new folder: one rename.
    if (!fs::exists(folder_, ec)) {
        fs::rename(work_, folder_, ec);
        if (ec)
            throw failed(work_);
        return;
    }
    // A folder that exists (empty, or holding files with -y): the frames and depth maps, then the
    // lists, each renamed over the file of the same name; the folder's other files stay.
    std::vector<std::string> names;
    for (const Entry& e : entries_) {
        if (!e.depth.empty())
            names.push_back(e.depth);
        names.push_back(e.color);
    }
    for (const char* list : {"depth.txt", "associations.txt", "rgb.txt"})
        if (fs::exists(work_ / list, ec))
            names.emplace_back(list);
    for (const std::string& name : names) {
        fs::create_directories((folder_ / name).parent_path(), ec);
        fs::rename(work_ / name, folder_ / name, ec);
        if (ec)
            throw failed(work_ / name);
    }
    fs::remove_all(work_, ec);
}

fs::path ImageSequenceSink::abandon(bool keep)
{
    if (finished_)
        return {};
    stopThreads(!keep);
    finished_ = true;
    // What was written after a failed frame is not kept: the kept frames have no gap.
    std::error_code ec;
    for (std::size_t i = written_; keep && i < entries_.size(); ++i) {
        fs::remove(work_ / entries_[i].color, ec);
        if (!entries_[i].depth.empty())
            fs::remove(work_ / entries_[i].depth, ec);
    }
    if (keep && written_ > 0)
        writeLists();
    return keepOrRemove(work_, folder_, true, keep, written_, "sequence");
}

std::string ImageSequenceSink::describe() const
{
    const std::lock_guard lock(mutex_);
    return fmt::format("{} sequence '{}' (TUM layout, {} frames)", linear_ ? "EXR" : "PNG", folder_.string(), written_);
}

SingleImageSink::SingleImageSink(fs::path file) : file_(std::move(file))
{
    const std::string ext = lowerExtension(file_);
    if (ext == ".exr")
        encoding_ = SinkEncoding::Linear32F;
    else if (ext == ".png" || ext == ".jpg" || ext == ".jpeg")
        encoding_ = SinkEncoding::Srgb8;
    else
        throw SinkError(fmt::format("cannot write image '{}': unsupported extension '{}' (use "
                                    ".png, .jpg or .exr)",
                                    file_.string(), ext));
    prepareFolder(file_.parent_path(), file_);
    work_ = temporaryPath(file_);
}

SingleImageSink::~SingleImageSink()
{
    try {
        abandon(false);
    } catch (const std::exception& e) {
        logger().error("{}", e.what());
    }
}

void SingleImageSink::write(const cv::Mat& image)
{
    if (finished_)
        throw SinkError(fmt::format("cannot write image '{}': already finished", file_.string()));
    checkFrame(image, encoding_, file_);
    writeImageAtomically(work_, image);
    ++written_;
}

void SingleImageSink::finish()
{
    if (finished_)
        return;
    finished_ = true;
    if (written_ == 0)
        return;
    std::error_code ec;
    fs::rename(work_, file_, ec);
    if (ec)
        throw SinkError(fmt::format("cannot write '{}': {}", file_.string(), ec.message()));
}

fs::path SingleImageSink::abandon(bool keep)
{
    if (finished_)
        return {};
    finished_ = true;
    return keepOrRemove(work_, file_, false, keep, written_, "image");
}

std::string SingleImageSink::describe() const
{
    return fmt::format("image '{}' ({})", file_.string(),
                       encoding_ == SinkEncoding::Linear32F ? "linear float" : "8-bit sRGB");
}

} // namespace defocus
