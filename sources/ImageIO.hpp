// Decoding of colour and depth images from disk into the forms the filter expects.
#pragma once

#include <filesystem>

#include <opencv2/core.hpp>

namespace defocus {

/// Reads a colour image. 8-bit files (PNG, JPEG, ...) give CV_8UC3 sRGB; grey or with alpha are
/// converted to BGR. 16-bit files give CV_32FC3 scene-linear (sRGB decoded). EXR and float TIFF
/// give CV_32FC3 scene-linear, unclipped. Throws SourceError naming the file on failure.
cv::Mat readColor(const std::filesystem::path& file);

/// Reads a depth image into CV_32FC1 metres. 16-bit integer images are divided by `unitsPerMetre`
/// (0 stays 0 = no measurement); float EXR/TIFF are taken as metres. 8-bit or multi-channel
/// images are rejected. Throws SourceError naming the file on failure.
cv::Mat readDepth(const std::filesystem::path& file, double unitsPerMetre);

} // namespace defocus
