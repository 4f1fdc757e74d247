#version 450 core
// Bokeh sprites, step 1 of 2 (issue 6, "highlights only where there are highlights"): every
// blurred pixel whose light the CoC pass gives to a sprite (highlights.glsl) appends one: its
// position, CoC and that light, to a buffer that is also the instanced draw's indirect command,
// so that no count comes back to the CPU. The buffer holds as many sprites as the scene analysis
// counted highlight pixels, a superset of these.
//
// One sprite per pixel: merging 2x2 blocks into one sprite at their light's centre made a
// quarter of the sprites but a staircase of the lights' edges, 1.1 dB worse on the Blender scene.
#include "common.glsl"
#include "coc_params.glsl"
#include "highlights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler2D uColor; // sRGB8 textures decode to linear on fetch
layout(binding = 1) uniform sampler2D uDepth; // metres, holes already filled

layout(std430, binding = 0) buffer Sprites {
    // DrawArraysIndirectCommand: 18 vertices (highlight_sprite.vert), four instances per sprite.
    uint vertexCount;
    uint instanceCount;
    uint firstVertex;
    uint baseInstance;
    uint capacity;
    uint unused[3];
    vec4 sprites[]; // per sprite: (x, y, signed CoC, 0), (light rgb, 0)
};

void main()
{
    const ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, textureSize(uDepth, 0))))
        return;
    const float coc = signedCoc(texelFetch(uDepth, texel, 0).r);
    const vec3 color = blurColor(texelFetch(uColor, texel, 0).rgb, coc);
    const float share = gatherShare(color, coc, texel, textureSize(uDepth, 0));
    if (share >= 1.0)
        return;
    // Four instances per sprite: itself and its mirror images in the frame's edges
    // (highlight_sprite.vert).
    const uint index = atomicAdd(instanceCount, 4u) / 4u;
    if (index < capacity) {
        sprites[2u * index] = vec4(vec2(texel) + 0.5, coc, 0.0);
        sprites[2u * index + 1u] = vec4(color * (1.0 - share), 0.0);
    }
}
