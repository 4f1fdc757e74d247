// SPDX-License-Identifier: LGPL-2.1-or-later
// Reads an image's format and size from its header, without decoding a pixel, so that a file that
// claims absurd dimensions or was cut short is rejected before OpenCV allocates or decodes.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace defocus {

/// The formats defocus decodes. Anything else OpenCV could open (DICOM, JPEG 2000, GDAL rasters,
/// PNM, ...) is refused: each decoder is attack surface, and none of them carries RGB-D footage.
enum class ImageFormat { Png, Jpeg, Tiff, Bmp, WebP, OpenExr };

std::string_view formatName(ImageFormat format);

struct ImageHeader {
    ImageFormat format = ImageFormat::Png;
    std::uint64_t width = 0;  ///< pixels, > 0 when `problem` is empty
    std::uint64_t height = 0; ///< pixels, > 0 when `problem` is empty
    /// Largest tile a tiled TIFF declares, pixels (its decoder allocates one tile); else 0.
    std::uint64_t tilePixels = 0;
    /// Why the file cannot be decoded, e.g. "truncated PNG: it ends inside chunk IDAT at byte
    /// 600"; empty when the header is sound. Completeness is checked where the format makes it
    /// cheap: PNG chunks up to IEND, JPEG markers up to EOI, the chunk table of a scan-line EXR,
    /// the RIFF size of WebP. TIFF and BMP are only checked for a readable size.
    std::string problem;
};

/// Recognises the format by its signature (not the file name) and reads width and height.
/// Never throws, never reads outside `bytes`.
ImageHeader readImageHeader(std::span<const unsigned char> bytes);

} // namespace defocus
