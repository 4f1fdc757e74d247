// SPDX-License-Identifier: LGPL-2.1-or-later
// Shared by the decoder fuzz targets: OpenCV set up once, quietly, and the header check that
// every decoded image must agree with.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include "fuzz/FuzzSupport.hpp"
#include "sources/ImageHeader.hpp"
#include "sources/ImageIO.hpp"

namespace defocus::fuzz {

/// Small enough that libFuzzer's 2 GB RSS limit holds with every conversion of a 16-bit RGBA
/// image under ASan; the limit code is the same as at kMaxImagePixels.
inline constexpr std::size_t kMaxPixels = std::size_t{1} << 20;

inline void setUpOpenCv()
{
    enableOpenExr();
    cv::setNumThreads(0);
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
}

/// A decoded image has the size its header gave (the size limit is enforced on the header, so a
/// decoder that disagreed would bypass it) and stays within the limit.
inline void checkAgainstHeader(std::span<const unsigned char> bytes, const cv::Mat& image)
{
    const ImageHeader header = readImageHeader(bytes);
    FUZZ_CHECK(header.problem.empty(), "decoded although the header check failed: %s", header.problem.c_str());
    FUZZ_CHECK(image.total() <= kMaxPixels, "decoded %dx%d, over the limit", image.cols, image.rows);
    // A TIFF whose orientation tag says it is stored rotated comes out with width and height
    // swapped: the same number of pixels, so the limit still holds.
    const auto cols = static_cast<std::uint64_t>(image.cols), rows = static_cast<std::uint64_t>(image.rows);
    const bool swapped = header.format == ImageFormat::Tiff && cols == header.height && rows == header.width;
    FUZZ_CHECK((cols == header.width && rows == header.height) || swapped,
               "%s header says %llux%llu, decoded %dx%d", formatName(header.format).data(),
               static_cast<unsigned long long>(header.width), static_cast<unsigned long long>(header.height),
               image.cols, image.rows);
}

} // namespace defocus::fuzz
