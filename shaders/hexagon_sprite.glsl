// The bokeh sprite's hexagon, shared by highlight_sprite.vert and .frag.

layout(std430, binding = 0) readonly buffer Sprites {
    uint vertexCount; // DrawArraysIndirectCommand (highlight_sprites.comp)
    uint instanceCount;
    uint firstVertex;
    uint baseInstance;
    uint capacity;
    uint found;
    uint unused[2];
    vec4 sprites[];   // per sprite: (x, y, signed CoC, 0), (light rgb, 0)
};

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
