#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Upscale (Resolution::Half): the frame-sized result from the half-size (or quarter-size:
// BLUR_SCALE 0.25, DETAIL_BELOW_PX 4) blur R of C (the CoC pass's target), by way of
// upscale_prefilter.frag's S (R sharpened) and D = R - C. With bil() the bilinear interpolation
// at the pixel's centre:
//
//   interpolated = bil(S)                      the blur, as sharp as the half size holds it
//   kept         = frame + bil(D)              the frame's own pixel plus what the blur added
//   out          = mix(interpolated, kept, w)  w = 1 for |CoC| <= 1 px, 0 from 2 px
//
// Where the blur left the half-size pixels alone (in focus, no foreground over them) D == 0, so
// an in-focus pixel comes out exactly as it came in; where a blurred foreground lies over it,
// the foreground adds to it; where the pixel is itself blurred by 2 px or more, the interpolated
// blur is all there is (detail of that size is what the lens removes).
//
// (2 px is DETAIL_BELOW_PX, set from kUpscaleDetailBelowPx in filter/SceneAnalysis.hpp, where
// the plan finds the tiles that have such pixels; the others are drawn by INTERPOLATE_ONLY:
// llvmpipe runs a branch's body for every pixel, so an `if` would not spare them the fetches.)
#include "common.glsl"
#include "coc_params.glsl"
#include "highlights.glsl"

layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uColor;     // the frame (sRGB8 decodes to linear on fetch)
layout(binding = 1) uniform sampler2D uDepth;     // the frame's filled depth, metres
layout(binding = 2) uniform sampler2D uSharpened; // half size: S (bilinear)
layout(binding = 3) uniform sampler2D uAdded;     // half size: D (bilinear)

void main()
{
    // Half-size texel i covers the frame's pixels 2i and 2i + 1, so its centre lies at 2i + 1:
    // in the half-size texture's coordinates the pixel's centre is at half of its own (a
    // quarter at quarter size, BLUR_SCALE).
    const vec2 uv = gl_FragCoord.xy * BLUR_SCALE / vec2(textureSize(uSharpened, 0));
    // S lies within its neighbourhood's range of the (non-negative) blur: so does its
    // interpolation.
    const vec3 interpolated = textureLod(uSharpened, uv, 0.0).rgb;
#ifdef INTERPOLATE_ONLY
    outColor = vec4(interpolated, 1.0);
#else
    const ivec2 texel = ivec2(gl_FragCoord.xy);
    const float coc = signedCoc(texelFetch(uDepth, texel, 0).r);
    const float w = clamp((DETAIL_BELOW_PX - abs(coc)) / (0.5 * DETAIL_BELOW_PX), 0.0, 1.0);
    vec3 result = interpolated;
    if (w > 0.0) {
        vec3 frame = sanitizeColor(texelFetch(uColor, texel, 0).rgb, largestColor);
        // Frames with bokeh sprites: a light in focus entered the blur as its stand-in (coc.frag,
        // standIn()), and so it is kept here; InFocusLightPass adds the rest by the share of the
        // pixel that no blurred foreground covers (in_focus_light.frag).
        if (highlightThreshold > 0.0 && abs(coc) < 1.0)
            frame = standIn(uColor, texel, frame);
        const vec3 kept = frame + textureLod(uAdded, uv, 0.0).rgb;
        // Not mix() at w = 1: x + 1 * (y - x) need not be y to the last bit.
        result = max(w >= 1.0 ? kept : interpolated + w * (kept - interpolated), vec3(0.0));
    }
    outColor = vec4(result, 1.0);
#endif
}
