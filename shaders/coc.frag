#version 450 core
// CoC pass (McIntosh et al. 2012, pass 1): linear colour in rgb, signed circle-of-confusion
// diameter in pixels in alpha (near < 0 < far). The CPU derived the madd coefficients
// (filter/Lens.cpp); here c = scale * x + offset with x = 1/z for the thin lens, x = z for the
// focal-range model.
#include "common.glsl"

layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uColor; // sRGB8 textures decode to linear on fetch
layout(binding = 1) uniform sampler2D uDepth; // metres, holes already filled

layout(std140, binding = 0) uniform CocParams {
    vec4 coefficients; // nearScale, nearOffset, farScale, farOffset
    float focusM;
    float maxCocPx;
    int inverseDepth;
    float largestColor; // 65504 for half-float targets
};

void main()
{
    const ivec2 texel = ivec2(gl_FragCoord.xy);
    const vec3 color = texelFetch(uColor, texel, 0).rgb;
    const float z = texelFetch(uDepth, texel, 0).r;
    const float x = inverseDepth != 0 ? 1.0 / z : z;
    const vec2 k = z < focusM ? coefficients.xy : coefficients.zw;
    const float coc = clamp(k.x * x + k.y, -maxCocPx, maxCocPx);
    outColor = vec4(sanitizeColor(color, largestColor), coc);
}
