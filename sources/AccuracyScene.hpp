// SPDX-License-Identifier: LGPL-2.1-or-later
// A scene folder for the accuracy benchmark: pinhole colour, planar depth, a thin-lens truth and
// scene.json describing the lens that made the truth. `defocus-bench accuracy --scene DIR` reads
// one folder, or every scene folder inside a corpus folder (data/corpus, docs/accuracy.md).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "filter/Settings.hpp"

namespace defocus {

/// scene.json, as parsed. Paths are relative to the scene folder in the file and absolute here.
///   {"description": "...",                      optional
///    "color": "color_linear.exr",               EXR (scene-linear) or PNG (sRGB)
///    "depth": "depth_mm.png",                   16-bit PNG or float EXR/TIFF in metres
///    "depthUnitsPerMetre": 1000,                16-bit depth only; default 1000
///    "truth": "truth_linear.exr",
///    "lens": {"focalLengthMm": 50, "sensorWidthMm": 36, "fNumber": 1.8, "focusM": 1.2,
///             "blades": 6, "bladeRotationDeg": 0, "fieldOfView": "focal-length",
///             "apertureRatio": 1},                   optional; blades 0 = circular
///    "render": {...}}                            optional, kept as text for the report
struct AccuracyScene {
    std::string name; ///< the folder's name
    std::filesystem::path dir;
    std::string description;
    std::filesystem::path color, depth, truth;
    double depthUnitsPerMetre = 1000.0;
    /// Thin-lens model, the fields above; maxCocPx is left at its default (the benchmark sets it
    /// from the scene's depth so that nothing is clamped).
    LensSettings lens;
    /// How close the truth is to converged, dB, as its renderer estimated it; NaN when unknown.
    double truthEstimatedPsnrDb = 0.0;
};

/// Parses the text of a scene.json that lives in `dir`. Throws SourceError naming
/// "DIR/scene.json" and the offending field: not JSON, a missing or mistyped field, or a value
/// outside the filter's range (blades other than 0 or 3 to 16 among them).
AccuracyScene parseAccuracyScene(std::string_view json, const std::filesystem::path& dir);

/// Reads DIR/scene.json and checks that the three image files exist. Throws SourceError.
AccuracyScene loadAccuracyScene(const std::filesystem::path& dir);

/// The scene folders `path` names: itself when it holds a scene.json, else every direct
/// subfolder that does, sorted by name. Throws SourceError when there is none.
std::vector<std::filesystem::path> findAccuracyScenes(const std::filesystem::path& path);

/// The images of a scene: colour and truth CV_32FC3 linear BGR, depth CV_32FC1 metres, all
/// the same size. Throws SourceError naming the file.
struct AccuracyImages {
    cv::Mat color, depth, truth;
};
AccuracyImages readAccuracyImages(const AccuracyScene& scene);

} // namespace defocus
