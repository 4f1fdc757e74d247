#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Near field (foreground) layer: the McIntosh gather leaves the silhouette of a blurred
// foreground object sharp, where a real lens spreads it over whatever is behind. This pass
// blurs a premultiplied layer of the foreground (pixels with CoC <= -0.5 px, coverage 1) with
// the same three directional blurs, using the largest foreground CoC that can reach each pixel
// (tile maxima dilated on the CPU) instead of the pixel's own; the composite lays it over the
// result by its blurred coverage.
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uSource;     // first pass: rgb + signed CoC; then premultiplied layer
layout(binding = 2) uniform sampler2D uNearRadius; // per tile: dilated foreground CoC diameter, pixels

layout(std140, binding = 0) uniform NearBlurParams {
    vec4 offsets[MAX_SAMPLES]; // as in hex_blur.frag: texture-space offset per pixel of diameter
    int sampleCount;
    int firstPass;             // 1: build the premultiplied layer from the CoC target on the fly
    float maxTapSpacing;       // pixels: large diameters keep every tap, small ones thin them
    float nearPad;
};

// The layer holds foreground blurred nearly as much (85 %) as the largest foreground that can
// reach this pixel: slightly-near surfaces (a floor running towards the camera) stay in the
// main result instead of being spread with a neighbour's much larger blur. On the Blender
// scene 30 %, 50 %, 70 % and 85 % gave 30.62, 30.67, 30.72 and 30.74 dB (30.26 without layer).
vec4 layer(vec4 texel, float diameter)
{
    if (firstPass == 0)
        return texel;
    return texel.a <= -max(0.5, 0.85 * diameter) ? vec4(texel.rgb, 1.0) : vec4(0.0);
}

void main()
{
    // The pixel centre from gl_FragCoord, not tiles.vert's interpolated uv, which rounds
    // otherwise and moved the bilinear taps by an ulp: the drawn pass and its compute form
    // (which has no interpolation) then differed by up to 5e-4.
    const vec2 vUv = gl_FragCoord.xy / vec2(textureSize(uSource, 0));
    const float diameter = textureLod(uNearRadius, vUv, 0.0).r;
    const vec4 center = layer(texelFetch(uSource, ivec2(gl_FragCoord.xy), 0), diameter);
    if (diameter < 0.5) {
        outColor = center;
        return;
    }
    const int intervals = sampleCount - 1;
    int stride = 1;
    for (int s = intervals; s > 1; --s)
        if (intervals % s == 0 && diameter * float(s) <= maxTapSpacing * float(intervals)) {
            stride = s;
            break;
        }
    vec4 sum = vec4(0.0);
    float count = 0.0;
    for (int i = 0; i < sampleCount; i += stride) {
        sum += layer(textureLod(uSource, vUv + offsets[i].xy * diameter, 0.0), diameter);
        count += 1.0;
    }
    outColor = sum / count;
}
