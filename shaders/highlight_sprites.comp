#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Bokeh sprites, step 1 of 2 (highlights only where there are highlights): every blurred pixel
// whose light the CoC pass gives to a sprite (highlights.glsl) makes one: its position, CoC and
// that light, in a buffer that is also the instanced draw's indirect command, so that no count
// comes back to the CPU. It holds the frame's budget of sprites; a frame with more draws none.
// Three dispatches put the sprites in one order whatever order the GPU runs them in (the draw
// adds them in that order, and float sums of overlapping sprites depend on it): COUNT marks, per
// tile of the list, the pixels that make a sprite; SETTLE turns the tiles' counts into each
// tile's first sprite and fills the draw's command; EMIT writes each sprite at its tile's first
// plus the pixels before it in the tile. The order: the tiles as listed, their pixels row by row.
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

struct TileSprites {
    uint first;   // COUNT: the tile's sprites; after SETTLE: the sprites of the tiles before it
    uint made[8]; // bit i: the tile's pixel i (row by row) makes a sprite
};

layout(std430, binding = 4) buffer Tiles {
    TileSprites tileSprites[]; // one per tile of the list
};

#ifdef SETTLE
// The tiles in the list.
layout(location = 0) uniform uint uTileCount;

layout(local_size_x = 256) in;

shared uint sSums[256];

// One work group: each invocation sums a run of consecutive tiles, the runs' sums are scanned,
// and each run's tiles get the sprites before them. A frame with more sprites than its budget
// draws none (the CoC pass then leaves their light in the gather: coc.frag), so that the draw
// costs at most the budget's hexagons whatever the picture.
void main()
{
    const uint i = gl_LocalInvocationIndex;
    const uint run = (uTileCount + 255u) / 256u;
    const uint begin = min(i * run, uTileCount), end = min(begin + run, uTileCount);
    uint sum = 0u;
    for (uint t = begin; t < end; ++t)
        sum += tileSprites[t].first;
    sSums[i] = sum;
    barrier();
    for (uint stride = 1u; stride < 256u; stride <<= 1) {
        const uint before = i >= stride ? sSums[i - stride] : 0u;
        barrier();
        sSums[i] += before;
        barrier();
    }
    uint first = sSums[i] - sum;
    for (uint t = begin; t < end; ++t) {
        const uint count = tileSprites[t].first;
        tileSprites[t].first = first;
        first += count;
    }
    if (i == 255u) {
        found = sSums[255];
        instanceCount = found <= capacity ? 4u * found : 0u;
    }
}
#else
// One work group per tile of the scene analysis that has pixels above the highlight threshold
// (no other pixel can make a sprite: highlights.glsl), from the list the CPU made of them.
layout(local_size_x = kTileSize, local_size_y = kTileSize) in;

#ifdef COUNT
shared uint sMade[8];
#endif

void main()
{
    const uint i = gl_LocalInvocationIndex;
    const ivec2 texel = highlightTiles[gl_WorkGroupID.x] * kTileSize + ivec2(gl_LocalInvocationID.xy);
#ifdef COUNT
    if (i < 8u)
        sMade[i] = 0u;
    barrier();
#else
    const uint word = i / 32u, bit = i % 32u;
    if ((tileSprites[gl_WorkGroupID.x].made[word] & (1u << bit)) == 0u || found > capacity)
        return;
#endif
    vec3 color = vec3(0.0);
    float coc = 0.0, share = 1.0;
    if (all(lessThan(texel, textureSize(uDepth, 0)))) {
        const vec3 raw = texelFetch(uColor, texel, 0).rgb;
        coc = signedCoc(texelFetch(uDepth, texel, 0).r);
        color = blurColor(raw, coc);
        share = spriteShare(color, coc, texel, textureSize(uDepth, 0));
    }
#ifdef COUNT
    if (share < 1.0)
        atomicOr(sMade[i / 32u], 1u << (i % 32u));
    barrier();
    if (i < 8u) {
        tileSprites[gl_WorkGroupID.x].made[i] = sMade[i];
        if (i == 0u) {
            uint count = 0u;
            for (int w = 0; w < 8; ++w)
                count += uint(bitCount(sMade[w]));
            tileSprites[gl_WorkGroupID.x].first = count;
        }
    }
#else
    // Its place: the tile's first, plus the tile's pixels before it that make one.
    uint index = tileSprites[gl_WorkGroupID.x].first + uint(bitCount(tileSprites[gl_WorkGroupID.x].made[word] &
                                                                      ((1u << bit) - 1u)));
    for (uint w = 0u; w < word; ++w)
        index += uint(bitCount(tileSprites[gl_WorkGroupID.x].made[w]));
    sprites[2u * index] = vec4(vec2(texel) + 0.5, coc, apertureArea(0.5 * abs(coc) / gatherScale));
    sprites[2u * index + 1u] = vec4(color * (1.0 - share), 0.0);
#endif
}
#endif
