// SPDX-License-Identifier: LGPL-2.1-or-later
// The bokeh sprite's hexagon, shared by highlight_sprites.comp and highlight_sprite.vert/.frag.

layout(std140, binding = 1) uniform SpriteParams {
    vec2 frameSize; // pixels
    vec2 corner;    // unit vector towards a corner, pixels (x right, y down)
    int nearField;  // QualitySettings::nearField: foreground blur spreads over what is behind it
};

// The share of the pixel at `offset` (pixels from the centre) that the regular hexagon of
// circumradius `radius` covers: its signed distance, the edges' normals 30 degrees from the
// corners, with half a pixel of ramp either side (the area a straight edge leaves a pixel).
float hexagonCoverage(vec2 offset, float radius)
{
    const vec2 n0 = vec2(0.866025 * corner.x - 0.5 * corner.y, 0.5 * corner.x + 0.866025 * corner.y);
    const vec2 n1 = vec2(0.5 * n0.x - 0.866025 * n0.y, 0.866025 * n0.x + 0.5 * n0.y);
    const vec2 n2 = vec2(-0.5 * n0.x - 0.866025 * n0.y, 0.866025 * n0.x - 0.5 * n0.y);
    const float distance =
        max(abs(dot(offset, n0)), max(abs(dot(offset, n1)), abs(dot(offset, n2)))) - 0.866025 * radius;
    return clamp(0.5 - distance, 0.0, 1.0);
}

// Below this circumradius the light is divided by the coverage summed over the pixels the
// hexagon touches, so that it is kept exactly (the ramp's area error is not negligible below a
// few pixels); above, by the hexagon's area, 3 sqrt(3) / 2 R^2 (within 0.7 %).
const float kSummedBelowRadius = 4.0;

float hexagonArea(float radius)
{
    if (radius >= kSummedBelowRadius)
        return 2.598076 * radius * radius;
    float area = 0.0;
    const int reach = int(ceil(radius + 0.5));
    for (int y = -reach; y <= reach; ++y)
        for (int x = -reach; x <= reach; ++x)
            area += hexagonCoverage(vec2(x, y), radius);
    return area;
}
