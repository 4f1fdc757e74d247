// SPDX-License-Identifier: LGPL-2.1-or-later
// The aperture's shape, as Blender Cycles samples it: a regular polygon of `blades` corners on the
// circle of the aperture's diameter (or that circle), rotated, its width divided by the
// anamorphic ratio. Lights scatter with its exact edges (the bokeh sprites); the gather of
// everything else is the rhombi's hexagon, squeezed as the aperture is and scaled to its area.
#pragma once

#include <array>

#include "filter/Settings.hpp"

namespace defocus {

struct ApertureShape {
    int blades = 6;          ///< 0 = circle
    float rotationDeg = 0.0f; ///< counter-clockwise in the image; at 0 an edge faces right
    float ratio = 1.0f;      ///< the width is divided by it

    static ApertureShape of(const LensSettings& lens);
    /// A regular hexagon, unsqueezed: the shape the rhombi gather draws exactly.
    bool isHexagon() const { return blades == 6 && ratio == 1.0f; }
    bool isCircle() const { return blades == 0; }
};

/// The shape's area for a circumradius of 1 (the CoC's radius): n/2 sin(2 pi / n) for a polygon,
/// pi for the circle, divided by the ratio.
double apertureArea(const ApertureShape& shape);

/// How the gather's hexagon is squeezed, in the image's axes: the aperture's squeeze (its
/// width divided by the ratio) over its larger factor, so that neither exceeds 1 and no line
/// reaches beyond the gather's CoC radius (gatherScale() holds the rest). {1, 1} unsqueezed.
struct GatherSqueeze {
    float x = 1.0f, y = 1.0f;
};
GatherSqueeze gatherSqueeze(const ApertureShape& shape);

/// The factor the gather's CoC is scaled by so that its hexagon (area 3 sqrt(3) / 2 R^2),
/// squeezed by gatherSqueeze(), covers the aperture's area: what a light spreads over is then
/// the aperture's, and the blur's spread (its second moment) is within 0.4 % of a circle's.
/// Exactly 1 for the hexagon.
float gatherScale(const ApertureShape& shape);

/// The sprites' edges (aperture_sprite.glsl), in pixels with y down the rows: for each edge
/// k < 16, the unit normal (x, y) and the distance of the edge from the centre per pixel of
/// circumradius; `count` edges, 0 for the circle.
struct ApertureEdges {
    std::array<float, 4 * 16> edges{}; ///< (nx, ny, distance per radius, 0) per edge
    int count = 0;
};
ApertureEdges apertureEdges(const ApertureShape& shape);

} // namespace defocus
