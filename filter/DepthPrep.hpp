// SPDX-License-Identifier: LGPL-2.1-or-later
// Depth as the CoC pass needs it: colour-sized, in metres, with every hole filled.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace defocus {

/// Depths at or below this (metres) are no measurement, like 0, negative, NaN and +-Inf.
inline constexpr float kMinValidDepthM = 1e-4f;

inline bool isValidDepth(float z)
{
    return z > kMinValidDepthM && z < std::numeric_limits<float>::infinity();
}

/// The range of valid depths in `depth` (any size: CV_32FC1 metres, or CV_16UC1 in
/// `unitsPerMetre` units, 0 where nothing was measured), in metres; `lo`/`hi` unchanged when there
/// is none. Returns the share of `depth` that is no measurement (1 when it is empty). Rows in bands
/// on OpenCV's threads, each row in SIMD lanes: it runs on the calling thread on every frame.
double validDepthRange(const cv::Mat& depth, double unitsPerMetre, float& lo, float& hi);

struct PreparedDepth {
    cv::Mat metres;                ///< CV_32FC1, colour-sized, every pixel valid
    double invalidFraction = 0.0;  ///< share of pixels that had no measurement, [0, 1]
};

/// Resizes `depth` (CV_32FC1 metres, any size) to `size` by nearest neighbour, so no depth is
/// invented between a foreground and a background, then fills holes by push-pull: a pyramid of
/// averages of the valid neighbours, coarse levels filling what finer ones cannot. A frame with
/// no valid depth at all (or no depth) becomes `fallbackM` everywhere.
PreparedDepth prepareDepth(const cv::Mat& depth, cv::Size size, float fallbackM);

/// The buffers prepareDepth() works in: the frame-sized weights and hole mask and a push-pull
/// pyramid, kept from frame to frame. Taken anew, buffers of megabytes come from the system a
/// page fault per 4 KB of first touch, and whether glibc keeps freed ones for the next frame
/// depends on what else the process allocates. The GStreamer element did not keep them: the
/// TUM clip at 1920x1080 took up to 100 ms a frame more without this workspace
/// (docs/benchmarks.md, "Buffers kept from frame to frame").
struct DepthPrepWorkspace {
    struct Level {
        cv::Mat weighted, weight, value, scratch, up;
        cv::Mat mask;
    };
    cv::Mat weight, holes, up;
    std::vector<Level> levels; ///< [0] unused; [1] half the frame's size, [2] a quarter, ...
};

/// prepareDepth() into `out`, with the buffers of `workspace` (grown as needed). out.metres is
/// written in place when it already has the size and type and nothing else refers to its buffer;
/// otherwise it is allocated anew.
void prepareDepth(const cv::Mat& depth, cv::Size size, float fallbackM, DepthPrepWorkspace& workspace,
                  PreparedDepth& out);

/// A pixel of `colorLinear` (CV_32FC3, linear BGR) above white (Rec. 709 luminance > 1) takes,
/// in `metres` (CV_32FC1, the same size, filled), the depth of the brightest pixel of its 3x3
/// neighbourhood when that one is brighter. A light's antialiased edge mixes the light with what
/// lies behind it or in front of it, and a renderer's depth (or a sensor's) gives such a pixel
/// one depth, the other surface's: its share of the light then took that surface's blur, a pale
/// hexagon as large as that blur around a light in front of a background, or beside the
/// nearer bar of a railing in front of a light (docs/accuracy.md, "What each improvement
/// bought"). The other surface's share of the pixel then takes the light's blur: one pixel's
/// worth. The brightest pixel's own depth can be the other surface's too, where only a sliver of
/// a light shows beside a nearer bar: a brightest pixel with a farther neighbour above white
/// across it from a dim one on the near side (nearer than halfway) is the nearer surface's edge
/// with the light beyond it, and gives that neighbour's depth (the farthest such). Decided on the
/// depth as it was. Returns the pixels changed.
std::size_t putLightEdgesAtTheirLightsDepth(const cv::Mat& colorLinear, cv::Mat& metres);

/// Depth of another size is resized to the colour, but only at the same aspect ratio: they agree
/// when the depth height is within one pixel (or 1 %) of depth width * colour height / colour
/// width. Returns "" when `depthSize` fits `colorSize`, otherwise one line naming both images
/// (`depthName`, `colorName`) and both sizes.
std::string depthFitProblem(const cv::Size& colorSize, const std::string& colorName, const cv::Size& depthSize,
                            const std::string& depthName);

/// Robust depth of the centre of the frame: the median of valid depths in the central
/// `windowFraction` of each axis; `fallbackM` when that window has no valid depth.
float centreDepth(const cv::Mat& depth, double windowFraction, float fallbackM);

} // namespace defocus
