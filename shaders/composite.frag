#version 450 core
// McIntosh composite: the per-channel minimum of the two rhombus blurs is their intersection,
// a hexagon with flat top and bottom edges. With NEAR_FIELD, the foreground layer (premultiplied,
// its own two rhombi -> hexagon the same way) goes over it by its coverage.
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
    vec3 color = min(texelFetch(uDiagonalA, texel, 0).rgb, texelFetch(uDiagonalB, texel, 0).rgb);
#ifdef NEAR_FIELD
    const vec4 near = min(texelFetch(uNearA, texel, 0), texelFetch(uNearB, texel, 0));
    color = near.rgb + (1.0 - clamp(near.a, 0.0, 1.0)) * color;
#endif
    outColor = vec4(color, 1.0);
}
