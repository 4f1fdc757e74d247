#version 450 core
// Scene analysis: each invocation measures one 16x16 tile of the frame: its depth
// range, how many of its pixels' |CoC| reach each histogram edge, and its highlight pixels, into
// one storage buffer that the CPU reads back and sums to make the frame's plan
// (filter/SceneAnalysis.cpp finishes it: CoC is monotonic in depth, so a tile's CoC range is the
// CoC of its depth range). filter/SceneAnalysis.cpp's measureScene() does the same on the CPU:
// keep the two in step.
//
// One invocation per tile, eight tiles per work group, and no shared memory: on llvmpipe the
// first version, a work group per tile with shared-memory atomics, took 6.2 ms at 640x480 where
// the CPU takes 1.4; the counts are cumulative (pixels with |CoC| >= each edge), so that no
// array is indexed by a run-time bin.
//
// EIGHT_BIT: the colour is an sRGB8 texture (decoded to linear on fetch) and a highlight is a
// pixel with a channel of 250 or more, as the CPU counts them in the encoded bytes: linear 0.9560
// for 250 and 0.9473 for 249, so the threshold sits between. Otherwise the colour is linear float
// and a highlight has a Rec. 709 luminance above 1.
#include "common.glsl"
#include "coc_params.glsl"
#include "scene_measurement.glsl"

layout(local_size_x = 8) in;

layout(binding = 0) uniform sampler2D uDepth; // metres, holes already filled: finite and > 0
layout(binding = 1) uniform sampler2D uColor;

const int kEdges = 8;
const float kHistogramEdges[kEdges] = float[](0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0);

// scene_measurement.glsl's layout (the luminance sum: the bokeh sprites compare a pixel with the
// mean of the 3x3 tiles around it, highlights.glsl).
layout(std430, binding = 0) writeonly buffer Measurement {
    uint words[];
};

void main()
{
    const ivec2 size = textureSize(uDepth, 0);
    const ivec2 tiles = (size + kTileSize - 1) / kTileSize;
    const ivec2 tile = ivec2(gl_GlobalInvocationID.xy);
    if (tile.x >= tiles.x)
        return;
    const ivec2 origin = tile * kTileSize;
    const ivec2 end = min(origin + kTileSize, size);

    float lo = 3.4e38, hi = 0.0;
    uint reach[kEdges] = uint[](0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u);
    uint highlights = 0u;
    float luminanceSum = 0.0;
    for (int y = origin.y; y < end.y; ++y)
        for (int x = origin.x; x < end.x; ++x) {
            const float z = texelFetch(uDepth, ivec2(x, y), 0).r;
            lo = min(lo, z);
            hi = max(hi, z);
            const float c = abs(signedCoc(z));
            for (int i = 0; i < kEdges; ++i)
                reach[i] += c >= kHistogramEdges[i] ? 1u : 0u;
            const vec3 color = texelFetch(uColor, ivec2(x, y), 0).rgb;
            const float brightness = luminance(color);
            luminanceSum += brightness;
#ifdef EIGHT_BIT
            highlights += max(color.r, max(color.g, color.b)) >= 0.9516 ? 1u : 0u;
#else
            highlights += brightness > 1.0 ? 1u : 0u;
#endif
        }

    const int base = measurementBase(origin, size);
    words[base + kMinDepthWord] = floatBitsToUint(lo);
    words[base + kMaxDepthWord] = floatBitsToUint(hi);
    for (int i = 0; i < kEdges; ++i)
        words[base + kFirstReachWord + i] = reach[i];
    words[base + kHighlightsWord] = highlights;
    words[base + kPixelsWord] = uint((end.x - origin.x) * (end.y - origin.y));
    words[base + kLuminanceWord] = floatBitsToUint(luminanceSum);
}
