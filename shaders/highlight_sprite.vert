#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Bokeh sprites, step 2: six triangles per sprite (highlight_sprites.comp), a hexagon just large
// enough for the sprite's aperture and the half pixel of its antialiased edge: for the
// hexagonal aperture the hexagon itself, of circumscribed diameter |CoC| (a quad around it shaded
// 38 % more pixels at 15 px); for other shapes the hexagon around their circumscribed circle,
// squeezed as they are.
#include "aperture_sprite.glsl"

layout(std430, binding = 0) readonly buffer Sprites {
    uint vertexCount; // DrawArraysIndirectCommand (highlight_sprites.comp)
    uint instanceCount;
    uint firstVertex;
    uint baseInstance;
    uint capacity;
    uint found;
    uint unused[2];
    vec4 sprites[];   // per sprite: (x, y, signed CoC of the gather, the aperture's area), (light rgb, 0)
};

layout(location = 0) out vec2 vOffset;     // pixels from the sprite's centre
layout(location = 1) flat out vec4 vLight; // rgb: light per pixel of full coverage; a: CoC
layout(location = 2) flat out float vRadius;

void main()
{
    const uint index = min(uint(gl_InstanceID) / 4u, capacity - 1u);
    vec4 sprite = sprites[2u * index];
    const vec3 light = sprites[2u * index + 1u].rgb;
    const float radius = 0.5 * abs(sprite.z) / gatherScale; // the lens' CoC
    const float area = sprite.w; // apertureArea(radius), once per sprite (highlight_sprites.comp)
    // Instances 1 to 3: the sprite mirrored in the nearer vertical edge, horizontal edge, or both,
    // so that light a hexagon would carry out of the frame comes back in, as the lights that lie
    // beyond it would bring theirs (and a bright region keeps its level up to the edges, as the
    // gather, which repeats the edge pixels, keeps it).
    // Mirror images that do not reach into the frame are collapsed to a point.
    const float fan = fanScale * radius + fanMargin;
    const vec2 reach = vec2(fan / ratio, fan);
    const int mirror = gl_InstanceID & 3;
    bool visible = true;
    if ((mirror & 1) != 0) {
        const bool left = sprite.x < 0.5 * frameSize.x;
        visible = visible && (left ? sprite.x < reach.x : frameSize.x - sprite.x < reach.x);
        sprite.x = left ? -sprite.x : 2.0 * frameSize.x - sprite.x;
    }
    if ((mirror & 2) != 0) {
        const bool top = sprite.y < 0.5 * frameSize.y;
        visible = visible && (top ? sprite.y < reach.y : frameSize.y - sprite.y < reach.y);
        sprite.y = top ? -sprite.y : 2.0 * frameSize.y - sprite.y;
    }
    // Triangle t of the fan: the centre, corner t, corner t + 1; the corners past the ramp: 0.7
    // px beyond the hexagon's edges (0.81 px along a corner), or the circle's.
    const int triangle = gl_VertexID / 3, vertex = gl_VertexID - 3 * triangle;
    vOffset = vec2(0.0);
    if (vertex != 0) {
        const float angle = 1.0471976 * float(triangle + vertex - 1); // 60 degrees a corner
        const vec2 direction = vec2(cos(angle) * fanCorner.x - sin(angle) * fanCorner.y,
                                    sin(angle) * fanCorner.x + cos(angle) * fanCorner.y);
        vOffset = visible ? direction * reach : vec2(0.0);
    }
    vLight = vec4(light / max(area, 1e-6), sprite.z);
    vRadius = radius;
    gl_Position = vec4((sprite.xy + vOffset) / frameSize * 2.0 - 1.0, 0.0, 1.0);
}
