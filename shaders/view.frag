#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Turns an intermediate target into something to look at: its colour as is, the filled depth
// on a log scale, or the signed CoC on a diverging scale (near blue, in focus white, far red).
#include "common.glsl"

layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uSource;

layout(std140, binding = 0) uniform ViewParams {
    int mode;        // 0 colour, 1 depth (red channel), 2 signed CoC (alpha channel)
    float rangeLow;  // depth: nearest metres on the scale; CoC: unused
    float rangeHigh; // depth: farthest metres; CoC: max CoC in pixels
    int sourceShift; // log2 of the target's size over the source's: 1 half, 2 quarter (Resolution::Half)
};

// Five-key ramp from dark violet (near) through teal and green to yellow (far), in sRGB.
vec3 depthRamp(float t)
{
    const vec3 keys[5] = vec3[](vec3(0.23, 0.05, 0.35), vec3(0.20, 0.30, 0.60), vec3(0.10, 0.60, 0.60),
                                vec3(0.40, 0.80, 0.30), vec3(0.99, 0.91, 0.15));
    const float s = clamp(t, 0.0, 1.0) * 4.0;
    const int i = min(int(s), 3);
    return mix(keys[i], keys[i + 1], s - float(i));
}

void main()
{
    const vec4 source = texelFetch(uSource, ivec2(gl_FragCoord.xy) >> sourceShift, 0);
    if (mode == 0) {
        outColor = vec4(source.rgb, 1.0);
    } else if (mode == 1) {
        const float t = log(source.r / rangeLow) / log(rangeHigh / rangeLow);
        outColor = vec4(srgbToLinear(depthRamp(t)), 1.0);
    } else {
        const float t = clamp(source.a / max(rangeHigh, 1e-6), -1.0, 1.0);
        const vec3 near = vec3(0.10, 0.35, 0.90), far = vec3(0.90, 0.25, 0.10);
        const vec3 c = t < 0.0 ? mix(vec3(1.0), near, -t) : mix(vec3(1.0), far, t);
        outColor = vec4(srgbToLinear(c), 1.0);
    }
}
