// SPDX-License-Identifier: LGPL-2.1-or-later
// CPU-side finishing of views: the legend of the colour-mapped views and the labelled contact
// sheet of all views of a frame.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace defocus {

enum class LegendKind {
    DepthMetres,    ///< log ramp, labels in metres
    SignedCocPixels ///< diverging ramp, labels in pixels (near negative)
};

/// Draws a colour bar with its end and middle labels along the bottom edge of `image`
/// (CV_8UC3 sRGB or CV_32FC3 linear). Images narrower than 160 px are left as they are.
void drawLegend(cv::Mat& image, LegendKind kind, float low, float high);

struct FramePlan;
struct SceneAnalysis;

/// The frame's plan drawn over `image` (CV_8UC3, frame-sized): tiles the blur passes process
/// outlined in orange, tiles only copied (in focus) dimmed, near-field tiles tinted blue.
cv::Mat drawTileMap(const cv::Mat& image, const FramePlan& plan, const SceneAnalysis& analysis);

/// Lays out labelled tiles (CV_8UC3) in a grid of `columns`, each with its label above it.
cv::Mat contactSheet(const std::vector<std::pair<std::string, cv::Mat>>& tiles, int columns = 4);

} // namespace defocus
