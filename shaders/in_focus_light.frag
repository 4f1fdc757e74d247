#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Lights in focus put back, on frames with bokeh sprites (InFocusLightPass). The CoC pass lets a
// light in focus (|CoC| < 1 px, above the highlight threshold) into the blur as what lies round
// it, its stand-in (coc.frag, SPRITES; standIn() in highlights.glsl), so that its HDR value does
// not light the blur around it; drawn additively over the output on the tiles with highlights,
// this pass adds E = light - stand-in by the share of the pixel that the blur left its own. At
// full size the blur's output of such a pixel is that share of the stand-in; at half size the
// upscale keeps the stand-in plus what the blur added to its texel (upscale.frag), and the share
// is the blur's at that texel.
//
// The rhombus blur (rhombus_blur.frag) returns an in-focus pixel as it is unless a blurred
// foreground reaches it (NEAR_FIELD); then each line gives alpha F + (1 - alpha) centre, where
// alpha is the foreground's coverage along that line (the taps' weights of the pixel's own blur
// are all 0 in focus). Through the chain
//
//   X = L1 s, Z = L2 s;   out = (L2 X + L3 X + L3 Z) / 3      (pass 1, then pass 2 fused)
//
// the centre's own value reaches the output by
//
//   share = ((1 - aA)(1 - aX) + (1 - aB)(1 - aX) + (1 - aB)(1 - aZ)) / 3
//
// with aX, aZ the coverages of pass 1's lines (u1, u2 over the CoC target) and aA, aB those of
// pass 2's (u2 over X, u3 over X and Z, the weights of X's taps). X keeps the CoC target's CoC in
// its alpha, so all four come from the CoC target's alpha, read the way each line reads its
// source (the same modes, steps and offsets: RhombusBlurPass::lines()). Added in full, the light
// showed through a blurred foreground that covers it (and went beyond the input's range).
#include "common.glsl"
#include "coc_params.glsl"
#include "highlights.glsl"
#include "rhombus_lines.glsl"

layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uColor;        // the frame
layout(binding = 1) uniform sampler2D uDepth;        // metres, holes filled
layout(binding = 2) uniform sampler2D uNearDiameter; // per tile, pixels (nearField only)
layout(binding = 3) uniform sampler2D uCoc;          // the CoC target: its alpha, unfiltered
layout(binding = 4) uniform sampler2D uCocSmooth;    // the same, bilinear

layout(std140, binding = 2) uniform InFocusLightParams {
    // Per line (pass 1: X along u1, Z along u2; pass 2: A along u2, B along u3): texture-space
    // offset per pixel along it (xy) and half a pixel across it (zw, PAIR lines).
    vec4 lineX, lineZ, lineA, lineB;
    vec4 baseSteps;   // the lines' steps that move one pixel on their major axis, pixels
    int maxTaps;      // the blur's taps per line at most
    int nearTileSize; // pixels per tile of uNearDiameter
    int nearField;    // 0: no foreground reaches any pixel
    int blurShift;    // log2 of the frame's size over the blur's (0 full size, 1 half)
};

// The foreground's coverage along one line, as rhombus_blur.frag's lines() sums it.
float coverage(const int mode, vec4 line, float baseStep, vec2 uv, float centerCoc, float extent)
{
    const float radius = 0.5 * abs(centerCoc);
    const LineSteps s = lineSteps(baseStep, extent, float(maxTaps));
    float sum = 0.0;
    for (int k = 1; k <= s.taps; ++k) {
        const float distance = float(k) * s.step;
        const float tapCoc = fetchTap(uCoc, uCocSmooth, mode, uv + line.xy * distance, line.zw, s.smoothing).a;
        sum += foregroundShare(foregroundReach(tapCoc, centerCoc, radius, distance, float(k), s.length), tapCoc,
                               s.step);
    }
    return clamp(sum, 0.0, 1.0);
}

void main()
{
    const ivec2 texel = ivec2(gl_FragCoord.xy);
    const float coc = signedCoc(texelFetch(uDepth, texel, 0).r);
    const vec3 color = blurColor(texelFetch(uColor, texel, 0).rgb, coc);
    if (abs(coc) >= 1.0 || luminance(color) <= highlightThreshold) {
        outColor = vec4(0.0);
        return;
    }
    // What the blur was given, as coc.frag gave it.
    const vec3 given = standIn(uColor, texel, color);
    float share = 1.0;
    if (nearField != 0) {
        // The blur's own view of the pixel: the CoC as its target holds it (a half float in
        // RGBA16F targets), and its lines as long as the foreground that can reach it.
        const ivec2 blurTexel = texel >> blurShift;
        const float centerCoc = texelFetch(uCoc, blurTexel, 0).a;
        const float extent = max(0.5 * abs(centerCoc), 0.5 * texelFetch(uNearDiameter, blurTexel / nearTileSize, 0).r);
        if (extent >= 0.5) {
            const vec2 uv = (vec2(blurTexel) + 0.5) / vec2(textureSize(uCoc, 0));
            const float aX = coverage(MODE_X, lineX, baseSteps.x, uv, centerCoc, extent);
            const float aZ = coverage(MODE_Z, lineZ, baseSteps.y, uv, centerCoc, extent);
            const float aA = coverage(MODE_A, lineA, baseSteps.z, uv, centerCoc, extent);
            const float aB = coverage(MODE_B, lineB, baseSteps.w, uv, centerCoc, extent);
            share = ((1.0 - aA) * (1.0 - aX) + (1.0 - aB) * (1.0 - aX) + (1.0 - aB) * (1.0 - aZ)) / 3.0;
        }
    }
    outColor = vec4(share * (color - given), 0.0);
}
