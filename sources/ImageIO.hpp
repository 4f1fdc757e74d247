// SPDX-License-Identifier: LGPL-2.1-or-later
// Decoding of colour and depth images from disk into the forms the filter expects.
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>

#include <opencv2/core.hpp>

namespace defocus {

/// Largest image accepted, in pixels: 2^27 = 134 million (16384 x 8192), four times an 8K UHD
/// frame. The size is read from the file header before anything is decoded, so a small file
/// that claims a huge size fails at once instead of allocating gigabytes.
inline constexpr std::size_t kMaxImagePixels = std::size_t{1} << 27;

/// Formats: PNG, JPEG, TIFF, BMP, WebP and OpenEXR, recognised by content, not by file name;
/// other formats OpenCV knows are refused. Truncated PNG, JPEG, WebP and scan-line EXR files are
/// caught from their structure (libjpeg alone would pad a cut JPEG with grey and carry on).

/// Lets OpenCV encode and decode OpenEXR (OPENCV_IO_ENABLE_OPENEXR=1) unless the environment
/// already holds a value, which is kept (even "0"). Call before OpenCV's first EXR imread or
/// imwrite; the readers and writers here do. Thread-safe; sets the variable once.
void enableOpenExr();

/// Reads a colour image. 8-bit files (PNG, JPEG, ...) give CV_8UC3 sRGB; grey or with alpha are
/// converted to BGR. 16-bit files give CV_32FC3 scene-linear (sRGB decoded). EXR and float TIFF
/// give CV_32FC3 scene-linear, unclipped. Throws SourceError naming the file on failure.
cv::Mat readColor(const std::filesystem::path& file);

/// readColor() of an encoded image held in memory; `name` stands for the file in messages.
/// Images over `maxPixels` are refused before decoding.
cv::Mat decodeColor(std::span<const unsigned char> bytes, const std::string& name,
                    std::size_t maxPixels = kMaxImagePixels);

/// A depth image as its file stored it: CV_16UC1 in `unitsPerMetre` units per metre, or CV_32FC1
/// metres (float files; `unitsPerMetre` 0).
struct StoredDepth {
    cv::Mat image;
    double unitsPerMetre = 0.0;
};

/// Reads a depth image as stored (readDepth() without the conversion to metres).
StoredDepth readStoredDepth(const std::filesystem::path& file, double unitsPerMetre);

/// Reads a depth image into CV_32FC1 metres. 16-bit integer images are divided by `unitsPerMetre`
/// (0 stays 0 = no measurement); float EXR/TIFF are taken as metres. 8-bit or multi-channel
/// images are rejected. Throws SourceError naming the file on failure.
cv::Mat readDepth(const std::filesystem::path& file, double unitsPerMetre);

/// readDepth() of an encoded image held in memory; `name` stands for the file in messages.
cv::Mat decodeDepth(std::span<const unsigned char> bytes, double unitsPerMetre, const std::string& name,
                    std::size_t maxPixels = kMaxImagePixels);

/// Depth of another size than its colour image is resized to it by the pipeline (a Kinect-style
/// 320x240 depth for 640x480 colour is fine), but only at the same aspect ratio: stretching a
/// 1:1 depth over a 4:3 frame would put every edge in the wrong place. Aspect ratios agree when
/// the depth height is within one pixel (or 1 %) of depth width * colour height / colour width.
/// Throws SourceError naming both files and both sizes when they do not.
void checkDepthFits(const cv::Size& colorSize, const std::string& colorName, const cv::Size& depthSize,
                    const std::string& depthName);

} // namespace defocus
