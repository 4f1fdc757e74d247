// Image sinks: numbered PNG/EXR sequences and single image files, each file written under a
// temporary name and renamed into place.
#include "sinks/ImageSinks.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <fstream>
#include <system_error>
#include <utility>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>

#include "filter/Log.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

constexpr int jpegQuality = 95;

// OpenCV reads OPENCV_IO_ENABLE_OPENEXR when it first encodes or decodes an EXR file; a value
// the user set (even "0") is left alone.
void enableOpenExr()
{
    static const bool enabled = [] {
        ::setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
        return true;
    }();
    (void)enabled;
}

std::string lowerExtension(const fs::path& file)
{
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

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

// Depth in metres as TUM stores it: 16-bit, 5000 units per metre, 0 = no measurement; depths past
// 13.1 m (the format's limit) are clamped to it.
cv::Mat tumDepth(const cv::Mat& metres)
{
    cv::Mat out(metres.size(), CV_16UC1);
    for (int y = 0; y < metres.rows; ++y)
        for (int x = 0; x < metres.cols; ++x) {
            const float d = metres.at<float>(y, x);
            const bool valid = std::isfinite(d) && d > 0.0f;
            out.at<std::uint16_t>(y, x) =
                valid ? static_cast<std::uint16_t>(std::min(65535.0f, std::round(d * 5000.0f))) : std::uint16_t{0};
        }
    return out;
}

} // namespace

ImageSequenceSink::ImageSequenceSink(fs::path folder, bool linear, double fps)
    : folder_(std::move(folder)), linear_(linear), fps_(fps > 0.0 ? fps : 30.0)
{
    std::error_code ec;
    createdFolder_ = !fs::exists(folder_, ec);
    prepareFolder(folder_, folder_);
}

ImageSequenceSink::~ImageSequenceSink()
{
    try {
        finish();
    } catch (const std::exception& e) {
        logger().error("{}", e.what());
    }
}

SinkEncoding ImageSequenceSink::encoding() const
{
    return linear_ ? SinkEncoding::Linear32F : SinkEncoding::Srgb8;
}

fs::path ImageSequenceSink::framePath(std::size_t index) const
{
    return index < entries_.size() ? folder_ / entries_[index].color : fs::path();
}

std::string ImageSequenceSink::nameFor(const Frame& origin)
{
    const fs::path name(origin.name);
    std::string stem = isImageName(name) ? name.stem().string() : std::string();
    if (stem.empty() || used_.count(stem) > 0)
        stem = fmt::format("frame_{:06}", written_);
    used_.insert(stem);
    return stem;
}

void ImageSequenceSink::write(const cv::Mat& image)
{
    Frame origin;
    origin.index = written_;
    writeFrame(image, origin);
}

void ImageSequenceSink::writeFrame(const cv::Mat& image, const Frame& origin)
{
    if (finished_)
        throw SinkError(fmt::format("cannot write sequence '{}': already finished", folder_.string()));
    const std::string stem = nameFor(origin);
    Entry entry{origin.timestamp > 0.0 ? origin.timestamp : static_cast<double>(written_) / fps_,
                stem + (linear_ ? ".exr" : ".png"), {}};
    const fs::path file = folder_ / entry.color;
    checkFrame(image, encoding(), file);
    if (!origin.depth.empty() && origin.depth.type() == CV_32FC1) {
        entry.depth = "depth/" + stem + ".png";
        std::error_code ec;
        fs::create_directories(folder_ / "depth", ec);
        writeImageAtomically(folder_ / entry.depth, tumDepth(origin.depth));
    }
    writeImageAtomically(file, image);
    entries_.push_back(entry);
    ++written_;
}

void ImageSequenceSink::finish()
{
    if (finished_)
        return;
    finished_ = true;
    std::error_code ec;
    if (written_ == 0) {
        if (createdFolder_ && fs::is_empty(folder_, ec) && fs::remove(folder_, ec))
            logger().warn("sequence '{}': no frames written, so the folder it created is removed",
                         folder_.string());
        return;
    }
    const auto list = [&](const char* what, auto line) {
        std::string text = fmt::format("# {}\n# file: written by defocus\n# timestamp {}\n", what,
                                       std::string(what) == "associations" ? "rgb timestamp depth" : "filename");
        for (const Entry& e : entries_)
            if (const std::string l = line(e); !l.empty())
                text += l + "\n";
        return text;
    };
    writeFileAtomically(folder_ / "rgb.txt",
                        list("color images", [](const Entry& e) { return fmt::format("{:.6f} {}", e.timestamp, e.color); }));
    const bool anyDepth = std::any_of(entries_.begin(), entries_.end(), [](const Entry& e) { return !e.depth.empty(); });
    if (!anyDepth)
        return;
    writeFileAtomically(folder_ / "depth.txt", list("depth maps", [](const Entry& e) {
                            return e.depth.empty() ? std::string() : fmt::format("{:.6f} {}", e.timestamp, e.depth);
                        }));
    writeFileAtomically(folder_ / "associations.txt", list("associations", [](const Entry& e) {
                            return e.depth.empty() ? std::string()
                                                   : fmt::format("{:.6f} {} {:.6f} {}", e.timestamp, e.color,
                                                                 e.timestamp, e.depth);
                        }));
}

std::string ImageSequenceSink::describe() const
{
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
}

void SingleImageSink::write(const cv::Mat& image)
{
    checkFrame(image, encoding_, file_);
    writeImageAtomically(file_, image);
    ++written_;
}

std::string SingleImageSink::describe() const
{
    return fmt::format("image '{}' ({})", file_.string(),
                       encoding_ == SinkEncoding::Linear32F ? "linear float" : "8-bit sRGB");
}

} // namespace defocus
