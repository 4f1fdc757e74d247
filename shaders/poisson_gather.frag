#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Riguer, Tatarchuk & Isidoro 2004, "Real-Time Depth of Field Simulation" (ShaderX2): a 12-tap
// Poisson disc around the centre, scaled by the centre's CoC radius, with their bleeding rule.
//
//          .   .            12 taps inside the unit disc (PoissonGatherPass::kTaps),
//       .    .    .         times the centre's CoC radius in pixels; the centre itself
//     .    . o  .   .       counts with weight 1
//       .    .   .
//
// Bleeding rule: a tap behind the centre counts fully; a tap in front of it counts with its own
// blurriness (|CoC| / max CoC, 0..1), so a sharp foreground does not smear onto a blurry
// background, and fades in as it blurs.
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uSource; // rgb + signed CoC (px) in alpha, linear filtering
layout(binding = 1) uniform sampler2D uDepth;  // metres, nearest filtering

layout(std140, binding = 0) uniform PoissonGatherParams {
    vec4 taps[12];  // xy: texture-space offset per pixel of CoC radius
    float maxCocPx; // blurriness = |CoC| / maxCocPx
};

void main()
{
    const ivec2 texel = ivec2(gl_FragCoord.xy);
    const vec4 center = texelFetch(uSource, texel, 0);
    const float radius = 0.5 * abs(center.a);
    if (radius < 0.25) { // a CoC below half a pixel is in focus: keep the pixel as it is
        outColor = center;
        return;
    }
    const float centerDepth = texelFetch(uDepth, texel, 0).r;
    vec3 sum = center.rgb;
    float total = 1.0;
    for (int i = 0; i < 12; ++i) {
        const vec2 coords = vUv + taps[i].xy * radius;
        const vec4 tap = textureLod(uSource, coords, 0.0);
        const float tapDepth = textureLod(uDepth, coords, 0.0).r;
        const float weight = tapDepth > centerDepth ? 1.0 : clamp(abs(tap.a) / maxCocPx, 0.0, 1.0);
        sum += tap.rgb * weight;
        total += weight;
    }
    outColor = vec4(sum / total, center.a);
}
