// SPDX-License-Identifier: LGPL-2.1-or-later
// The aperture's shape: its area, the gather's scale, the sprites' edges.
#include "filter/Aperture.hpp"

#include <cmath>
#include <numbers>

namespace defocus {

namespace {

constexpr double kHexagonArea = 2.598076211353316; // 3 sqrt(3) / 2

} // namespace

ApertureShape ApertureShape::of(const LensSettings& lens)
{
    return {lens.blades, static_cast<float>(lens.bladeRotationDeg), static_cast<float>(lens.apertureRatio)};
}

double apertureArea(const ApertureShape& shape)
{
    const double n = shape.blades;
    const double unit = shape.isCircle() ? std::numbers::pi : 0.5 * n * std::sin(2.0 * std::numbers::pi / n);
    return unit / static_cast<double>(shape.ratio);
}

GatherSqueeze gatherSqueeze(const ApertureShape& shape)
{
    // The aperture's width is divided by the ratio: (1 / ratio, 1), over the larger.
    if (shape.ratio >= 1.0f)
        return {1.0f / shape.ratio, 1.0f};
    return {1.0f, shape.ratio};
}

float gatherScale(const ApertureShape& shape)
{
    if (shape.isHexagon())
        return 1.0f;
    // The squeezed hexagon of circumradius k R covers k^2 x y 3 sqrt(3) / 2 R^2; the aperture
    // covers apertureArea() R^2 (its own squeeze included).
    const GatherSqueeze squeeze = gatherSqueeze(shape);
    return static_cast<float>(std::sqrt(apertureArea(shape) / (kHexagonArea * squeeze.x * squeeze.y)));
}

ApertureEdges apertureEdges(const ApertureShape& shape)
{
    ApertureEdges out;
    if (shape.isCircle())
        return out;
    // Cycles samples the polygon with an edge's normal at the rotation (x right, y up) and its
    // corners pi / n either side of it, at the unit circle: the edges lie cos(pi / n) from the
    // centre. Squeezed, a point p of the unit shape lands at (p.x / ratio, p.y): the edge
    // n . p = d becomes (ratio n.x, n.y) . q = d, whose unit normal and distance are taken here.
    // y is flipped for the image's rows.
    const double n = shape.blades;
    const double apothem = std::cos(std::numbers::pi / n);
    for (int k = 0; k < shape.blades; ++k) {
        const double angle = (shape.rotationDeg * std::numbers::pi / 180.0) + 2.0 * std::numbers::pi * k / n;
        const double nx = std::cos(angle) * shape.ratio, ny = std::sin(angle);
        const double length = std::hypot(nx, ny);
        out.edges[4 * k + 0] = static_cast<float>(nx / length);
        out.edges[4 * k + 1] = static_cast<float>(-ny / length);
        out.edges[4 * k + 2] = static_cast<float>(apothem / length);
    }
    out.count = shape.blades;
    return out;
}

} // namespace defocus
