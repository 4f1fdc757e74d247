// SPDX-License-Identifier: LGPL-2.1-or-later
// The CoC of a depth, shared by the CoC pass (coc.frag) and the half-size upscale
// (upscale.frag): the CPU derived the madd coefficients (filter/Lens.cpp); c = scale * x + offset
// with x = 1/z for the thin lens, x = z for the focal-range model. Signed diameter in pixels of
// the frame (near < 0 < far), clamped to max-coc.

layout(std140, binding = 0) uniform CocParams {
    vec4 coefficients; // nearScale, nearOffset, farScale, farOffset
    float focusM;
    float maxCocPx;
    int inverseDepth;
    float largestColor;  // 65504 for half-float targets
    float highlightGain; // 8-bit input: near-clipped pixels that get blurred are scaled up to this
    // Luminance above which a blurred pixel's light goes to a bokeh sprite (highlights.glsl);
    // 0: none does.
    float highlightThreshold;
};

float signedCoc(float z)
{
    const float x = inverseDepth != 0 ? 1.0 / z : z;
    const vec2 k = z < focusM ? coefficients.xy : coefficients.zw;
    return clamp(k.x * x + k.y, -maxCocPx, maxCocPx);
}
