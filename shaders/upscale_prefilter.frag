#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Upscale prefilter (Resolution::Half), at half size: sharpens the blurred result so that the
// bilinear upscale after it keeps its detail. Each frame-sized pixel centre lies a quarter of a
// half-size texel from the nearest texel centre, so the upscale weighs texels 3/4 and 1/4 along
// each axis: an alternating row of texels (the highest frequency the half-size image holds)
// comes out at half its contrast. The prefilter
//
//   S = (1 + k) R - k B(R),   B = [1 2 1] x [1 2 1] / 16,   k = 1
//
// is [-k/4, 1 + k/2, -k/4] along each axis: it passes flat areas unchanged and that alternating
// row at 1 + k = 2 times its contrast, so prefilter and upscale together pass it whole. On the
// Blender scene it took the half-size blur from 31.5 to 33 dB (docs/accuracy.md): the edges of
// bokeh shapes and blurred objects come out as sharp as the truth's.
//
// S is clamped to the range of its 3x3 neighbourhood (the anti-ringing of image upscalers).
// Unclamped, the undershoot beside an HDR light's bokeh went below zero and drew a dark ring
// round it (clamped at 0 by the upscale, which also added 3 % to a light's energy on black);
// clamped, the ring is gone, for 0.05 dB less on the Blender scene (33.05 against 33.10 dB) and
// 0.09 dB more at 4 taps.
//
// The second target takes D = R - C, what the blur added to its input C, for the upscale's
// in-focus pixels (upscale.frag): zero, exactly, wherever the blur left a pixel alone.

layout(location = 0) out vec4 outSharpened;
layout(location = 1) out vec4 outAdded;

layout(binding = 0) uniform sampler2D uBlurred; // R, half size
layout(binding = 1) uniform sampler2D uInput;   // C, half size

void main()
{
    const ivec2 pixel = ivec2(gl_FragCoord.xy);
    const ivec2 last = textureSize(uBlurred, 0) - 1;
    vec3 binomial = vec3(0.0), lo = vec3(3.4e38), hi = vec3(0.0);
    for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i) {
            const vec3 c = texelFetch(uBlurred, clamp(pixel + ivec2(i, j), ivec2(0), last), 0).rgb;
            binomial += c * (float((2 - abs(i)) * (2 - abs(j))) / 16.0);
            lo = min(lo, c);
            hi = max(hi, c);
        }
    const vec3 centre = texelFetch(uBlurred, pixel, 0).rgb;
    outSharpened = vec4(clamp(2.0 * centre - binomial, lo, hi), 1.0); // k = 1
    outAdded = vec4(centre - texelFetch(uInput, pixel, 0).rgb, 1.0);
}
