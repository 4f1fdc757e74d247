#version 450 core
// McIntosh composite: the per-channel minimum of the two rhombus blurs is their intersection,
// a hexagon with flat top and bottom edges.
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uDiagonalA;
layout(binding = 1) uniform sampler2D uDiagonalB;

void main()
{
    const ivec2 texel = ivec2(gl_FragCoord.xy);
    outColor = vec4(min(texelFetch(uDiagonalA, texel, 0).rgb, texelFetch(uDiagonalB, texel, 0).rgb), 1.0);
}
