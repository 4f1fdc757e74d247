#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// What a frame's pixels say, for the plan (SceneMeasurePass): one work group per 16x16 tile of
// the frame measures its depth range, its highlight pixels, its summed linear luminance and the
// depth's holes, and the frame's |CoC| histogram; measureScene() (filter/SceneAnalysis.cpp) does the same on the
// CPU. A few kilobytes come back instead of the frame: the plan is made from them
// (finishAnalysis()).
#include "coc_params.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

layout(binding = 0) uniform sampler2D uDepth; // metres, filled
// 8-bit frames: the sRGB bytes (an RGB8 view of the sRGB8 texture, undecoded), decoded by the
// CPU's own table; float frames: linear.
layout(binding = 1) uniform sampler2D uColor;
uniform bool uEightBit;
// DepthPrepPass::measured(): g = 0 where the depth as it came had no measurement; its holes are
// counted when uCountHoles is set (not for a frame without depth, which is all hole).
layout(binding = 2) uniform sampler2D uMeasured;
uniform bool uCountHoles;
uniform float uDecode[256]; // srgbToLinear(i / 255)

struct Tile {
    float minDepth;
    float maxDepth;
    uint highlights;
    float luminance;
};

layout(std430, binding = 0) buffer Measurement {
    uint invalidPixels; // the depth's holes
    uint bins[9];       // pixels per |CoC| bin: below 0.5, 1, 2, 4, 8, 16, 32, 64 px, and the rest
    uint unused[2];
    Tile tiles[];       // row by row
};

const float kHistogramEdges[8] = float[8](0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0);

shared float sMin[256];
shared float sMax[256];
shared float sLuminance[256];
shared uint sHighlights[256];
shared uint sHoles[256];
shared uint sBins[9];

void main()
{
    const uint i = gl_LocalInvocationIndex;
    if (i < 9u)
        sBins[i] = 0u;
    barrier();

    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    const ivec2 size = textureSize(uDepth, 0);
    float lo = 3.4e38, hi = -3.4e38, luminance = 0.0;
    uint highlight = 0u, hole = 0u;
    if (all(lessThan(p, size))) {
        if (uCountHoles)
            hole = texelFetch(uMeasured, p, 0).g == 0.0 ? 1u : 0u;
        const float z = texelFetch(uDepth, p, 0).r;
        lo = z;
        hi = z;
        const float c = abs(signedCoc(z));
        uint bin = 0u;
        for (int e = 0; e < 8; ++e)
            bin += c >= kHistogramEdges[e] ? 1u : 0u;
        atomicAdd(sBins[bin], 1u);
        vec3 rgb = texelFetch(uColor, p, 0).rgb;
        if (uEightBit) {
            // Highlights: a channel clipped by the camera (250 or more).
            const ivec3 bytes = ivec3(round(rgb * 255.0));
            highlight = max(bytes.r, max(bytes.g, bytes.b)) >= 250 ? 1u : 0u;
            rgb = vec3(uDecode[bytes.r], uDecode[bytes.g], uDecode[bytes.b]);
        }
        luminance = 0.0722 * rgb.b + 0.7152 * rgb.g + 0.2126 * rgb.r; // Rec. 709, the CPU's order
        if (!uEightBit)
            highlight = luminance > 1.0 ? 1u : 0u; // float: above white
    }
    sMin[i] = lo;
    sMax[i] = hi;
    sLuminance[i] = luminance;
    sHighlights[i] = highlight;
    sHoles[i] = hole;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1) {
        if (i < stride) {
            sMin[i] = min(sMin[i], sMin[i + stride]);
            sMax[i] = max(sMax[i], sMax[i + stride]);
            sLuminance[i] += sLuminance[i + stride];
            sHighlights[i] += sHighlights[i + stride];
            sHoles[i] += sHoles[i + stride];
        }
        barrier();
    }
    if (i == 0u) {
        tiles[gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x] =
            Tile(sMin[0], sMax[0], sHighlights[0], sLuminance[0]);
        if (sHoles[0] > 0u)
            atomicAdd(invalidPixels, sHoles[0]);
    }
    if (i < 9u && sBins[i] > 0u)
        atomicAdd(bins[i], sBins[i]);
}
