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
    float highlightGain; // 8-bit input: near-clipped pixels that get blurred are scaled up to this
};

// Highlights from 8-bit video (issue 6): a light clipped at 255 is far brighter than 1.0, and a
// blur of its clipped value spreads a dull grey. Pixels whose brightest channel is within the
// top 4 % of the range are scaled up towards highlightGain, smoothly from 0.96 to 1.0 (linear),
// so that lights bloom into bright polygons; only where the pixel will be blurred (|CoC| >= 1 px),
// so that pixels in focus stay as they are.
vec3 recoverHighlight(vec3 color, float coc)
{
    if (highlightGain <= 1.0 || abs(coc) < 1.0)
        return color;
    const float peak = max(color.r, max(color.g, color.b));
    return color * mix(1.0, highlightGain, smoothstep(0.96, 1.0, peak));
}

void main()
{
    const ivec2 texel = ivec2(gl_FragCoord.xy);
    const vec3 color = texelFetch(uColor, texel, 0).rgb;
    const float z = texelFetch(uDepth, texel, 0).r;
    const float x = inverseDepth != 0 ? 1.0 / z : z;
    const vec2 k = z < focusM ? coefficients.xy : coefficients.zw;
    const float coc = clamp(k.x * x + k.y, -maxCocPx, maxCocPx);
    outColor = vec4(sanitizeColor(recoverHighlight(color, coc), largestColor), coc);
}
