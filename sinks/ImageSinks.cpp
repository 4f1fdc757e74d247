// Image sinks: numbered PNG/EXR sequences and single image files, each file written under a
// temporary name and renamed into place.
#include "sinks/ImageSinks.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <system_error>
#include <utility>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>

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

// imwrite to ".NAME.partial.EXT" next to `file` (same file system, extension kept so OpenCV picks
// the same encoder), then rename over `file`: readers never see a half-written image.
void writeAtomically(const fs::path& file, const cv::Mat& image)
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

} // namespace

ImageSequenceSink::ImageSequenceSink(fs::path folder, bool linear)
    : folder_(std::move(folder)), linear_(linear)
{
    std::error_code ec;
    createdFolder_ = !fs::exists(folder_, ec);
    prepareFolder(folder_, folder_);
    if (fs::exists(framePath(0), ec))
        spdlog::warn("sequence '{}': the folder already holds frames; they will be overwritten",
                     folder_.string());
}

SinkEncoding ImageSequenceSink::encoding() const
{
    return linear_ ? SinkEncoding::Linear32F : SinkEncoding::Srgb8;
}

fs::path ImageSequenceSink::framePath(std::size_t index) const
{
    return folder_ / fmt::format("frame_{:06}{}", index, linear_ ? ".exr" : ".png");
}

void ImageSequenceSink::write(const cv::Mat& image)
{
    const fs::path file = framePath(written_);
    checkFrame(image, encoding(), file);
    writeAtomically(file, image);
    ++written_;
}

void ImageSequenceSink::finish()
{
    if (finished_)
        return;
    finished_ = true;
    std::error_code ec;
    if (written_ == 0 && createdFolder_ && fs::is_empty(folder_, ec) && fs::remove(folder_, ec))
        spdlog::warn("sequence '{}': no frames written, so the folder it created is removed",
                     folder_.string());
}

std::string ImageSequenceSink::describe() const
{
    return fmt::format("{} sequence '{}' (frame_NNNNNN{}, {} frames)", linear_ ? "EXR" : "PNG",
                       folder_.string(), linear_ ? ".exr" : ".png", written_);
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
    writeAtomically(file_, image);
    ++written_;
}

std::string SingleImageSink::describe() const
{
    return fmt::format("image '{}' ({})", file_.string(),
                       encoding_ == SinkEncoding::Linear32F ? "linear float" : "8-bit sRGB");
}

} // namespace defocus
