// SPDX-License-Identifier: LGPL-2.1-or-later
// The CPU reference of the methods registry: every pixel scatters its aperture polygon with the
// exact area it covers of each destination pixel, depth-ordered and normalised. The best a single
// RGB-D layer can give; slow (seconds per 640x480 frame), and meant to be.
#pragma once

#include <opencv2/core.hpp>

namespace defocus {

struct ScatterOptions {
    /// Two contributions to one destination pixel belong to different depth layers when, sorted
    /// by signed CoC, no chain of contributions closer than this (pixels of CoC, > 0) joins them.
    /// Within a layer light adds up (a continuous surface does not occlude itself); a nearer
    /// layer occludes the farther ones with its coverage as alpha. 2 px measured best on the
    /// Blender scene among 0.25, 0.5, 1, 2 and 4 (34.43 dB at 1 px, 34.57 at 2 and 4; 33.86 dB
    /// with no occlusion at all).
    float layerGapPx = 2.0f;
    /// Aperture blades: the polygon's corner count, [3, 16].
    int blades = 6;
    /// Polygon rotation, degrees counter-clockwise on screen, as LensSettings::bladeRotationDeg:
    /// 0 puts a corner on top, which is what Blender Cycles renders for "blade rotation 0" (its
    /// regular_polygon_sample() centres an edge, not a corner, on its rotation angle). For 6
    /// blades, 30 gives flat top and bottom edges, the McIntosh chain's hexagon.
    float rotationDeg = 0.0f;
};

/// Exact area of the intersection of the regular polygon of `options` (blades, rotation) with
/// circumradius `radius`, centred at (cx, cy), and the axis-aligned unit square whose top-left
/// corner is (x, y) (image coordinates, y down).
double polygonSquareOverlap(const ScatterOptions& options, double cx, double cy, double radius, double x, double y);

/// Scatters every pixel of `linear` (CV_32FC3 scene-linear, HDR kept; finite, >= 0) as the
/// aperture polygon (by default a regular hexagon with a corner on top) whose
/// circumscribed diameter is |CoC| from `cocPx` (CV_32FC1 signed CoC diameter in pixels, near <
/// 0 < far). The light of a pixel is spread evenly over its polygon (hexagon area
/// 3 sqrt(3) / 8 d^2): each destination pixel receives colour * overlap / area, so light that
/// stays inside the image is conserved exactly.
///
/// Occlusion, per destination pixel: its contributions are sorted far to near by signed CoC and
/// cut into layers wherever consecutive CoCs differ by more than `layerGapPx`. A layer's light
/// and coverage add up; a layer with total coverage above 1 is normalised to 1. Layers are then
/// composited far to near with the painter's `over`: colour = layer + (1 - coverage) * colour,
/// alpha = coverage + (1 - coverage) * alpha. The result is colour / alpha, i.e. normalised, so
/// that background hidden in the input (behind a blurred foreground, or beyond the border) is
/// filled by what is visible around it. Pixels with |CoC| <= 1 (circumradius <= 0.5) stay within
/// their own pixel, so an all-in-focus image comes back unchanged.
///
/// Multithreaded over bands of destination rows (OpenCV's parallel_for_); deterministic.
cv::Mat referenceScatter(const cv::Mat& linear, const cv::Mat& cocPx, const ScatterOptions& options = {});

} // namespace defocus
