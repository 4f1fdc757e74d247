// SPDX-License-Identifier: LGPL-2.1-or-later
// Decodes colour and depth images from disk into the frame formats the filter expects
// (colour: 8-bit sRGB or float linear BGR; depth: float metres).
#include "sources/ImageIO.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "filter/DepthPrep.hpp"
#include "sources/FrameSource.hpp"
#include "sources/ImageHeader.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

std::string describeSamples(const cv::Mat& image)
{
    static constexpr const char* depthNames[] = {"8-bit unsigned", "8-bit signed", "16-bit unsigned",
                                                 "16-bit signed",  "32-bit integer", "32-bit float",
                                                 "64-bit float",   "16-bit float"};
    const int channels = image.channels();
    return fmt::format("{} with {} channel{}", depthNames[image.depth()], channels,
                       channels == 1 ? "" : "s");
}

bool isFloat(const cv::Mat& image)
{
    return image.depth() == CV_32F || image.depth() == CV_64F || image.depth() == CV_16F;
}

std::vector<unsigned char> readBytes(const fs::path& file, const char* what)
{
    std::error_code ec;
    if (!fs::exists(file, ec))
        throw SourceError(
            fmt::format("cannot read {} image '{}': file does not exist", what, file.string()));
    if (fs::is_directory(file, ec))
        throw SourceError(
            fmt::format("cannot read {} image '{}': it is a folder", what, file.string()));
    std::ifstream in(file, std::ios::binary);
    std::vector<unsigned char> bytes;
    if (in)
        bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (!in && !in.eof())
        throw SourceError(fmt::format("cannot read {} image '{}': {}", what, file.string(),
                                      std::generic_category().message(errno)));
    return bytes;
}

// Checks the header (format, size, completeness), then decodes with IMREAD_UNCHANGED: the caller
// decides what each bit depth and channel count means. `file`, when given, is decoded from disk
// (OpenCV's EXR decoder cannot read from memory and would copy the bytes to a temporary file).
cv::Mat decode(std::span<const unsigned char> bytes, const std::string& name, const char* what,
               std::size_t maxPixels, const fs::path* file)
{
    enableOpenExr();
    // OpenCV's own hard limit on each side (CV_IO_MAX_IMAGE_WIDTH and _HEIGHT).
    constexpr std::uint64_t maxSide = std::uint64_t{1} << 20;
    const ImageHeader header = readImageHeader(bytes);
    if (!header.problem.empty())
        throw SourceError(fmt::format("cannot read {} image '{}': {}", what, name, header.problem));
    if (header.width > maxSide || header.height > maxSide || header.width * header.height > maxPixels)
        throw SourceError(fmt::format("cannot read {} image '{}': the {} header gives {}x{} pixels, more "
                                      "than the {} allowed ({} per side)",
                                      what, name, formatName(header.format), header.width, header.height,
                                      maxPixels, maxSide));
    if (header.tilePixels > maxPixels)
        throw SourceError(fmt::format("cannot read {} image '{}': its TIFF tiles have {} pixels, more than "
                                      "the {} allowed",
                                      what, name, header.tilePixels, maxPixels));
    if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
        throw SourceError(fmt::format("cannot read {} image '{}': files over 2 GiB are not supported",
                                      what, name));
    cv::Mat image;
    try {
        if (file && header.format == ImageFormat::OpenExr) {
            image = cv::imread(file->string(), cv::IMREAD_UNCHANGED);
        } else {
            const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1,
                                  const_cast<unsigned char*>(bytes.data()));
            image = cv::imdecode(encoded, cv::IMREAD_UNCHANGED);
        }
    } catch (const cv::Exception& e) {
        throw SourceError(fmt::format("cannot read {} image '{}': {}", what, name, e.err));
    }
    if (image.empty())
        throw SourceError(fmt::format("cannot read {} image '{}': the {} decoder failed (corrupt data)",
                                      what, name, formatName(header.format)));
    return image;
}

// Grey -> BGR, BGRA -> BGR (alpha dropped); any depth cvtColor supports (8U, 16U, 32F).
cv::Mat toBgr(const cv::Mat& image, const std::string& name)
{
    cv::Mat bgr;
    switch (image.channels()) {
    case 1:
        cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
        return bgr;
    case 3:
        return image;
    case 4:
        cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
        return bgr;
    default:
        throw SourceError(fmt::format(
            "cannot read colour image '{}': it is {}; expected 1 (grey), 3 (colour) or 4 "
            "(colour + alpha) channels",
            name, describeSamples(image)));
    }
}

// sRGB EOTF (IEC 61966-2-1), exact piecewise form, tabulated for every 16-bit code value:
//   c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055)^2.4,   c = code / 65535.
const std::vector<float>& srgb16ToLinear()
{
    static const std::vector<float> table = [] {
        std::vector<float> t(65536);
        for (std::size_t code = 0; code < t.size(); ++code) {
            const double c = static_cast<double>(code) / 65535.0;
            t[code] = static_cast<float>(c <= 0.04045 ? c / 12.92
                                                      : std::pow((c + 0.055) / 1.055, 2.4));
        }
        return t;
    }();
    return table;
}

cv::Mat decode16BitSrgb(const cv::Mat& bgr16)
{
    const std::vector<float>& table = srgb16ToLinear();
    cv::Mat linear(bgr16.size(), CV_32FC3);
    const int valuesPerRow = bgr16.cols * 3;
    for (int y = 0; y < bgr16.rows; ++y) {
        const auto* in = bgr16.ptr<std::uint16_t>(y);
        auto* out = linear.ptr<float>(y);
        for (int i = 0; i < valuesPerRow; ++i)
            out[i] = table[in[i]];
    }
    return linear;
}

cv::Mat colorFromRaw(const cv::Mat& raw, const std::string& name)
{
    if (raw.depth() == CV_8U)
        return toBgr(raw, name);
    if (raw.depth() == CV_16U)
        return decode16BitSrgb(toBgr(raw, name));
    if (isFloat(raw)) {
        cv::Mat f;
        raw.convertTo(f, CV_32F);
        return toBgr(f, name);
    }
    throw SourceError(fmt::format(
        "cannot read colour image '{}': it is {}; expected 8-bit, 16-bit or float samples", name,
        describeSamples(raw)));
}

void checkDepthScale(double unitsPerMetre, const std::string& name)
{
    if (!(unitsPerMetre > 0.0) || !std::isfinite(unitsPerMetre))
        throw SourceError(fmt::format(
            "cannot read depth image '{}': the depth scale must be a positive number of units "
            "per metre, got {}",
            name, unitsPerMetre));
}

StoredDepth storedDepthFromRaw(const cv::Mat& raw, double unitsPerMetre, const std::string& name)
{
    if (raw.depth() == CV_16U && raw.channels() == 1)
        return {raw, unitsPerMetre};
    if (isFloat(raw) && (raw.channels() == 1 || raw.channels() == 3 || raw.channels() == 4)) {
        // Renderers often store depth replicated in R, G and B: take the first channel.
        cv::Mat first = raw;
        if (raw.channels() > 1)
            cv::extractChannel(raw, first, 0);
        cv::Mat metres;
        first.convertTo(metres, CV_32F);
        return {metres, 0.0};
    }
    throw SourceError(fmt::format(
        "cannot read depth image '{}': it is {}; expected 16-bit single-channel ({} units per "
        "metre) or float metres (EXR, TIFF)",
        name, describeSamples(raw), unitsPerMetre));
}

// 0 (no measurement) stays 0.
cv::Mat metres(const StoredDepth& depth)
{
    Frame frame;
    frame.depth = depth.image;
    frame.depthScale = depth.unitsPerMetre;
    return depthMetres(frame);
}

} // namespace

// OpenCV reads OPENCV_IO_ENABLE_OPENEXR when it first encodes or decodes an EXR file, so setting
// it before then is enough.
void enableOpenExr()
{
    static const bool enabled = [] {
        ::setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0); // 0: a value the user set (even "0") stays
        return true;
    }();
    (void)enabled;
}

cv::Mat decodeColor(std::span<const unsigned char> bytes, const std::string& name, std::size_t maxPixels)
{
    return colorFromRaw(decode(bytes, name, "colour", maxPixels, nullptr), name);
}

cv::Mat readColor(const fs::path& file)
{
    const std::vector<unsigned char> bytes = readBytes(file, "colour");
    return colorFromRaw(decode(bytes, file.string(), "colour", kMaxImagePixels, &file), file.string());
}

cv::Mat decodeDepth(std::span<const unsigned char> bytes, double unitsPerMetre, const std::string& name,
                    std::size_t maxPixels)
{
    checkDepthScale(unitsPerMetre, name);
    return metres(storedDepthFromRaw(decode(bytes, name, "depth", maxPixels, nullptr), unitsPerMetre, name));
}

StoredDepth readStoredDepth(const fs::path& file, double unitsPerMetre)
{
    checkDepthScale(unitsPerMetre, file.string());
    const std::vector<unsigned char> bytes = readBytes(file, "depth");
    return storedDepthFromRaw(decode(bytes, file.string(), "depth", kMaxImagePixels, &file), unitsPerMetre,
                              file.string());
}

cv::Mat readDepth(const fs::path& file, double unitsPerMetre)
{
    return metres(readStoredDepth(file, unitsPerMetre));
}

void checkDepthFits(const cv::Size& colorSize, const std::string& colorName, const cv::Size& depthSize,
                    const std::string& depthName)
{
    if (const std::string problem = depthFitProblem(colorSize, colorName, depthSize, depthName); !problem.empty())
        throw SourceError(problem);
}

} // namespace defocus
