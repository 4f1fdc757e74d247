#version 450 core
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
// bokeh shapes and blurred objects come out as sharp as the truth's. B is four bilinear taps,
// one at each corner of the texel (each the mean of a 2x2 block).
//
// The price is a small undershoot beside hard edges. On a black background it goes below zero,
// and the upscale clamps it to 0: a point light's bokeh there gains energy (3.0 % at a 15-px CoC,
// 1.1 % at 31 px, measured; on a grey background no loss or gain). Clamping S to its 3x3
// neighbourhood's range instead (the anti-ringing of image upscalers) halved that gain but cost
// the balanced preset 0.05 dB on the Blender scene; not adopted.
//
// The second target takes D = R - C, what the blur added to its input C, for the upscale's
// in-focus pixels (upscale.frag): zero, exactly, wherever the blur left a pixel alone.

layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outSharpened;
layout(location = 1) out vec4 outAdded;

layout(binding = 0) uniform sampler2D uBlurred; // R, half size, bilinear
layout(binding = 1) uniform sampler2D uInput;   // C, half size

void main()
{
    const vec2 texel = 1.0 / vec2(textureSize(uBlurred, 0));
    const ivec2 pixel = ivec2(gl_FragCoord.xy);
    const vec3 centre = texelFetch(uBlurred, pixel, 0).rgb;
    const vec3 binomial = 0.25 * (textureLod(uBlurred, vUv + vec2(-0.5, -0.5) * texel, 0.0).rgb +
                                  textureLod(uBlurred, vUv + vec2(0.5, -0.5) * texel, 0.0).rgb +
                                  textureLod(uBlurred, vUv + vec2(-0.5, 0.5) * texel, 0.0).rgb +
                                  textureLod(uBlurred, vUv + vec2(0.5, 0.5) * texel, 0.0).rgb);
    outSharpened = vec4(2.0 * centre - binomial, 1.0); // k = 1
    outAdded = vec4(centre - texelFetch(uInput, pixel, 0).rgb, 1.0);
}
