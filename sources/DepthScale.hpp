// SPDX-License-Identifier: LGPL-2.1-or-later
// Depth that cannot silently be at the wrong scale: the median valid depth of a frame is held
// against the distances a scene from a depth sensor can have, and a frame outside them gets one
// warning with the likely fix.   defocus realsense_in_tum_layout/ -o out.mp4
//   defocus: warning: depth of rgb/1.png: median 0.28 m at 5000 units per metre, nearer than
//   depth sensors measure; if its 16-bit depth is in millimetres, add --depth-scale 1000 (median 1.40 m)
#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace defocus {

/// Below this median valid depth a scene is nearer than the depth sensors measure (Kinect v1 and
/// Azure Kinect from 0.5 m, RealSense D435 from about 0.3 m at 848x480, Kinect v2 from 0.5 m).
constexpr double kNearestPlausibleMedianM = 0.4;
/// Above this median a scene is farther than they reach (Kinect v1 4-5 m, D435 about 10 m).
constexpr double kFarthestPlausibleMedianM = 20.0;

struct DepthScaleCheck {
    std::size_t validPixels = 0;            ///< depths > 0 and finite
    double medianM = 0.0;                   ///< median of the valid depths, metres
    std::optional<double> suggestedScale;   ///< a common scale that puts the median in range
    std::string warning;                    ///< one line; empty when the depth looks right
};

/// Checks the depth of one frame (CV_32FC1, metres, as sources deliver it) read at
/// `unitsPerMetre`; `where` names the frame for the warning. No valid depth: no warning.
DepthScaleCheck checkDepthScale(const cv::Mat& depthMetres, double unitsPerMetre, const std::string& where);

} // namespace defocus
