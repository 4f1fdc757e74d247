#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Bokeh sprites, step 1 of 2 (highlights only where there are highlights): every
// blurred pixel whose light the CoC pass gives to a sprite (highlights.glsl) appends one: its
// position, CoC and that light, to a buffer that is also the instanced draw's indirect command,
// so that no count comes back to the CPU. It holds the frame's budget of sprites; a frame with
// more draws none (SETTLE, below).
//
// One sprite per pixel: merging 2x2 blocks into one sprite at their light's centre made a
// quarter of the sprites but a staircase of the lights' edges, 1.1 dB worse on the Blender scene.
#include "common.glsl"
#include "coc_params.glsl"
#include "highlights.glsl"
#include "aperture_sprite.glsl"

layout(binding = 0) uniform sampler2D uColor; // sRGB8 textures decode to linear on fetch
layout(binding = 1) uniform sampler2D uDepth; // metres, holes already filled

layout(std430, binding = 0) buffer Sprites {
    // DrawArraysIndirectCommand: 18 vertices (highlight_sprite.vert), four instances per sprite.
    uint vertexCount;
    uint instanceCount;
    uint firstVertex;
    uint baseInstance;
    uint capacity; // the frame's budget of sprites
    uint found;    // the pixels that make one, counted past the budget
    uint unused[2];
    vec4 sprites[]; // per sprite: (x, y, signed CoC of the gather, the aperture's area), (light rgb, 0)
};

layout(std430, binding = 3) readonly buffer HighlightTiles {
    ivec2 highlightTiles[]; // column, row
};

#ifdef SETTLE
layout(local_size_x = 1) in;

// One invocation after the search: a frame with more sprites than its budget draws none (the
// CoC pass then leaves their light in the gather: coc.frag), so that the draw costs at most the
// budget's hexagons whatever the picture.
void main()
{
    if (found > capacity)
        instanceCount = 0u;
}
#else
// One work group per tile of the scene analysis that has pixels above the highlight threshold
// (no other pixel can make a sprite: highlights.glsl), from the list the CPU made of them.
layout(local_size_x = kTileSize, local_size_y = kTileSize) in;

void main()
{
    const ivec2 texel = highlightTiles[gl_WorkGroupID.x] * kTileSize + ivec2(gl_LocalInvocationID.xy);
    if (any(greaterThanEqual(texel, textureSize(uDepth, 0))))
        return;
    const vec3 raw = texelFetch(uColor, texel, 0).rgb;
    const float coc = signedCoc(texelFetch(uDepth, texel, 0).r);
    const vec3 color = blurColor(raw, coc);
    const float share = spriteShare(color, coc, texel, textureSize(uDepth, 0));
    if (share >= 1.0)
        return;
    const uint index = atomicAdd(found, 1u);
    if (index < capacity) {
        sprites[2u * index] = vec4(vec2(texel) + 0.5, coc, apertureArea(0.5 * abs(coc) / gatherScale));
        sprites[2u * index + 1u] = vec4(color * (1.0 - share), 0.0);
        // Four instances per sprite: itself and its mirror images in the frame's edges
        // (highlight_sprite.vert).
        atomicAdd(instanceCount, 4u);
    }
}
#endif
