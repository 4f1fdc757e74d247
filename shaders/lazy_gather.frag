#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// The "lazy" 8-point gather of the GameStudio wiki's depth-of-field article (after Scheuermann
// 2004): eight fixed points on the unit circle and square, scaled by the centre's CoC radius,
// averaged; a tap whose blurriness differs from the centre's by more than a threshold is
// replaced by the centre sample, so neither a sharp nor a much blurrier neighbour bleeds in.
//
//          x                (1,0) (-1,0) (0,1) (0,-1) and (+-0.4, +-0.4), times the CoC radius;
//       x     x             the centre is not a tap of its own
//     x    o    x
//       x     x
//          x
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uSource; // rgb + signed CoC (px) in alpha, linear filtering

layout(std140, binding = 0) uniform LazyGatherParams {
    vec4 taps[8];    // xy: texture-space offset per pixel of CoC radius
    float maxCocPx;  // blurriness = |CoC| / maxCocPx
    float threshold; // largest blurriness difference a tap may have, 0..1
};

void main()
{
    const vec4 center = texelFetch(uSource, ivec2(gl_FragCoord.xy), 0);
    const float radius = 0.5 * abs(center.a);
    if (radius < 0.25) { // a CoC below half a pixel is in focus: keep the pixel as it is
        outColor = center;
        return;
    }
    const float centerBlur = abs(center.a) / maxCocPx;
    vec3 sum = vec3(0.0);
    for (int i = 0; i < 8; ++i) {
        const vec4 tap = textureLod(uSource, vUv + taps[i].xy * radius, 0.0);
        sum += abs(abs(tap.a) / maxCocPx - centerBlur) > threshold ? center.rgb : tap.rgb;
    }
    outColor = vec4(sum / 8.0, center.a);
}
