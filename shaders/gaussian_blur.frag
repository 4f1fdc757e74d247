#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// The 5x5 Gaussian of the "Toy Story - Depth of Field" WebGL demo: spread = aperture x distance
// from the plane in focus, i.e. proportional to the centre's |CoC|. No bleeding rule.
//
//    . . . . .     25 taps on a grid whose step is |CoC| / 4, so the grid spans the CoC
//    . . . . .     diameter; weights exp(-(i^2 + j^2) / 2) (sigma = 1 step = |CoC| / 4, the
//    . . o . .     standard deviation of a uniform disc of that diameter), normalised on the
//    . . . . .     CPU (GaussianBlurPass)
//    . . . . .
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uSource; // rgb + signed CoC (px) in alpha, linear filtering

layout(std140, binding = 0) uniform GaussianBlurParams {
    vec4 taps[25]; // xy: texture-space offset per pixel of CoC diameter, z: weight (sum 1)
};

void main()
{
    const vec4 center = texelFetch(uSource, ivec2(gl_FragCoord.xy), 0);
    const float diameter = abs(center.a);
    if (diameter < 0.5) { // a CoC below half a pixel is in focus: keep the pixel as it is
        outColor = center;
        return;
    }
    vec3 sum = vec3(0.0);
    for (int i = 0; i < 25; ++i)
        sum += textureLod(uSource, vUv + taps[i].xy * diameter, 0.0).rgb * taps[i].z;
    outColor = vec4(sum, center.a);
}
