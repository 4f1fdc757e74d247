#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// The hexagon from the two results of the last blur pass.
//   McIntosh et al. 2012 (default): the per-channel minimum of the two rhombus blurs is their
//     intersection, a hexagon (flat edges parallel to the first pass). With NEAR_FIELD, the
//     foreground layer (premultiplied, its own two rhombi -> hexagon the same way) goes over it
//     by its coverage.
//   SUM: the three one-sided rhombi of rhombus_blur.frag, (A + 2 B) / 3, where B already holds
//     two of them averaged.
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uDiagonalA;
layout(binding = 1) uniform sampler2D uDiagonalB;
#ifdef NEAR_FIELD
layout(binding = 2) uniform sampler2D uNearA;
layout(binding = 3) uniform sampler2D uNearB;
#endif

void main()
{
    const ivec2 texel = ivec2(gl_FragCoord.xy);
    const vec3 a = texelFetch(uDiagonalA, texel, 0).rgb;
    const vec3 b = texelFetch(uDiagonalB, texel, 0).rgb;
#ifdef SUM
    vec3 color = b + (a - b) * (1.0 / 3.0); // (A + 2 B) / 3, and exactly A where A == B (in focus)
#else
    vec3 color = min(a, b);
#endif
#ifdef NEAR_FIELD
    const vec4 near = min(texelFetch(uNearA, texel, 0), texelFetch(uNearB, texel, 0));
    color = near.rgb + (1.0 - clamp(near.a, 0.0, 1.0)) * color;
#endif
    outColor = vec4(color, 1.0);
}
