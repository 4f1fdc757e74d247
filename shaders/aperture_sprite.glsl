// SPDX-License-Identifier: LGPL-2.1-or-later
// The bokeh sprite's shape, the lens' aperture (filter/Aperture.hpp), shared by
// highlight_sprites.comp and highlight_sprite.vert/.frag.

layout(std140, binding = 1) uniform SpriteParams {
    vec2 frameSize;    // pixels
    float ratio;       // anamorphic squeeze: the aperture's width is divided by it
    int edgeCount;     // the polygon's edges; 0 = the circle (an ellipse when squeezed)
    int nearField;     // QualitySettings::nearField: foreground blur spreads over what is behind it
    float gatherScale; // the gather's CoC over the lens' (gatherScale() in filter/Aperture.hpp)
    float fanScale;    // the drawn fan's circumradius: fanScale * radius + fanMargin, pixels
    float fanMargin;
    vec2 fanCorner;    // unit vector towards the fan's first corner, pixels (x right, y down)
    float unitArea;    // the shape's area at circumradius 1, pixels
    float padding;
    vec4 edges[16];    // per edge: unit normal (pixels, y down), distance per pixel of radius
};

// The share of the pixel at `offset` (pixels from the centre) that the aperture of circumradius
// `radius` covers: its signed distance with half a pixel of ramp either side (the area a straight
// edge leaves a pixel). In front of the focus (`near`) the lens images its aperture turned by
// 180 degrees (the rays cross before the focus plane), which only odd blade counts show.
float apertureCoverage(vec2 offset, float radius, bool near)
{
    const vec2 p = near ? -offset : offset;
    float distance;
    if (edgeCount == 0) {
        // The squeezed circle (x ratio)^2 + y^2 = radius^2: its level set's distance to first
        // order (exact for the circle).
        const vec2 s = vec2(p.x * ratio, p.y);
        const float level = length(s);
        const float gradient = level > 0.0 ? length(vec2(s.x * ratio, s.y)) / level : 1.0;
        distance = (level - radius) / gradient;
    } else {
        distance = dot(p, edges[0].xy) - radius * edges[0].z;
        for (int k = 1; k < edgeCount; ++k)
            distance = max(distance, dot(p, edges[k].xy) - radius * edges[k].z);
    }
    return clamp(0.5 - distance, 0.0, 1.0);
}

// Below this circumradius the light is divided by the coverage summed over the pixels the
// aperture touches, so that it is kept exactly (the ramp's area error is not negligible below a
// few pixels); above, by the shape's area, unitArea R^2 (within 0.7 % for the hexagon).
const float kSummedBelowRadius = 4.0;

float apertureArea(float radius)
{
    if (radius >= kSummedBelowRadius)
        return unitArea * radius * radius;
    float area = 0.0;
    const int reach = int(ceil(radius / min(ratio, 1.0) + 0.5));
    for (int y = -reach; y <= reach; ++y)
        for (int x = -reach; x <= reach; ++x)
            area += apertureCoverage(vec2(x, y), radius, false);
    return area;
}
