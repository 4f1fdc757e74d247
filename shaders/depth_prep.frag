#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Depth as the CoC pass needs it, on the GPU (DepthPrepPass): the depth as it came (any size, in
// metres) resized to the frame by nearest neighbour, so that no depth is invented between a
// foreground and a background, and its holes filled by push-pull (Gortler et al. 1996): a
// pyramid of weighted averages of the valid depths, each coarser level filling the holes the
// finer one cannot. The same arithmetic as prepareDepth() on the CPU (filter/DepthPrep.cpp), step
// for step, so that both give one filled depth (DepthPrepGLTest compares them).
//
// Fragment shaders, one full-screen triangle per step and level: every step writes each pixel
// of its target once, which a render target takes fastest on llvmpipe (its compute shaders'
// image and buffer stores took 20 to 25 ns a pixel: 35 ms for this at 640x480), and the steps are
// a few cheap taps a pixel on any GPU.
//
// Each pyramid level is RG32F: r = the level's depth (a weighted mean), g = its weight in [0, 1],
// 1 where the level's pixel is fully measured. One variant per step:
//   SPLIT        level 0, the frame's size, from the depth as it came (g = 0: a hole)
//   PUSH         level k from level k - 1: the weighted mean of each 2x2 block (area-weighted
//                where a size is odd)
//   PULL         level k's depth with its holes blended from level k + 1's, already filled (the
//                coarsest level is its own mean), into an R32F target
//   FILL         the filled depth: level 0's measured pixels, the rest from level 1
//   LIGHT_EDGES  float frames with bokeh sprites: a light's antialiased edge takes the light's
//                depth (putLightEdgesAtTheirLightsDepth(), filter/DepthPrep.hpp)

#if defined(SPLIT) || defined(PUSH)
layout(location = 0) out vec2 outLevel;
#else
layout(location = 0) out float outDepth;
#endif

layout(location = 0) uniform ivec2 uSize; // the target's (DepthPrepPass::kSizeLocation)

// prepareDepth(): depths at or below kMinValidDepthM (1e-4 m), NaN and +-Inf are no measurement.
bool isValidDepth(float z)
{
    return z > 1e-4 && !isinf(z);
}

// Upsampled as cv::resize's INTER_LINEAR does: pixel centres mapped onto the coarse grid,
// clamped at its edges, weights in full float (a sampler's are 8-bit fractions on most GPUs).
float upsampled(sampler2D coarse, ivec2 p)
{
    const ivec2 size = textureSize(coarse, 0);
    const vec2 at = max((vec2(p) + 0.5) * vec2(size) / vec2(uSize) - 0.5, vec2(0.0));
    const ivec2 i0 = min(ivec2(at), size - 1);
    const ivec2 i1 = min(i0 + 1, size - 1);
    const vec2 f = at - vec2(i0);
    const float top = mix(texelFetch(coarse, i0, 0).r, texelFetch(coarse, ivec2(i1.x, i0.y), 0).r, f.x);
    const float bottom = mix(texelFetch(coarse, ivec2(i0.x, i1.y), 0).r, texelFetch(coarse, i1, 0).r, f.x);
    return mix(top, bottom, f.y);
}

#if defined(SPLIT)

#if defined(UNITS)
// R16UI as a 16-bit depth file or camera gives it, 0 where nothing was measured; any size.
layout(binding = 0) uniform usampler2D uDepth;
// A unit in metres, as a float (DepthPrepPass::kMetresPerUnitLocation). A product is correctly
// rounded (a quotient may be 2.5 ulp off), so the metres are those cv::Mat::convertTo makes.
layout(location = 2) uniform float uMetresPerUnit;
float metresAt(ivec2 texel)
{
    return float(texelFetch(uDepth, texel, 0).r) * uMetresPerUnit;
}
#else
layout(binding = 0) uniform sampler2D uDepth; // R32F metres as it came, any size
float metresAt(ivec2 texel)
{
    return texelFetch(uDepth, texel, 0).r;
}
#endif

void main()
{
    const ivec2 p = ivec2(gl_FragCoord.xy);
    // cv::resize's INTER_NEAREST: source pixel floor(p * source size / frame size).
    const ivec2 source = textureSize(uDepth, 0);
    const float z = metresAt(min(p * source / uSize, source - 1));
    const bool valid = isValidDepth(z);
    outLevel = vec2(valid ? z : 0.0, valid ? 1.0 : 0.0);
}

#elif defined(PUSH)

layout(binding = 0) uniform sampler2D uFiner;

void main()
{
    const ivec2 p = ivec2(gl_FragCoord.xy);
    // The sums of depth * weight and of weight over the block of the finer level under this
    // pixel, as cv::resize's INTER_AREA takes them: 2x2 pixels where the finer size is even; where
    // it is odd the block is 2 * size / (size + 1) pixels wide, its edge pixels weighed by the
    // share of them it covers.
    const ivec2 finer = textureSize(uFiner, 0);
    const vec2 scale = vec2(finer) / vec2(uSize);
    const vec2 from = vec2(p) * scale, to = from + scale;
    vec2 sum = vec2(0.0);
    for (int y = int(from.y); y < min(int(ceil(to.y)), finer.y); ++y) {
        const float wy = min(float(y + 1), to.y) - max(float(y), from.y);
        for (int x = int(from.x); x < min(int(ceil(to.x)), finer.x); ++x) {
            const float w = wy * (min(float(x + 1), to.x) - max(float(x), from.x));
            const vec2 texel = texelFetch(uFiner, ivec2(x, y), 0).rg;
            sum += w * vec2(texel.r * texel.g, texel.g);
        }
    }
    const vec2 mean = sum / (scale.x * scale.y);
    // A coarse pixel is fully trusted once its block held one full sample's worth of weight.
    outLevel = vec2(mean.x / max(mean.y, 1e-12), min(4.0 * mean.y, 1.0));
}

#elif defined(PULL)

layout(binding = 0) uniform sampler2D uLevel;   // rg: depth, weight
layout(binding = 1) uniform sampler2D uCoarser; // r: filled

void main()
{
    const ivec2 p = ivec2(gl_FragCoord.xy);
    const vec2 level = texelFetch(uLevel, p, 0).rg;
    outDepth = level.r * level.g + upsampled(uCoarser, p) * (1.0 - level.g);
}

#elif defined(FILL)

layout(binding = 0) uniform sampler2D uLevel0;   // r: depth, g: 1 measured, 0 a hole
layout(binding = 1) uniform sampler2D uLevel1;   // r: filled
layout(binding = 2) uniform sampler2D uCoarsest; // 1x1: g > 0 when the frame has any measurement
layout(location = 1) uniform float uFallbackM; // the whole frame's depth when nothing was measured

void main()
{
    const ivec2 p = ivec2(gl_FragCoord.xy);
    const vec2 level = texelFetch(uLevel0, p, 0).rg;
    outDepth = level.g > 0.0                              ? level.r
               : texelFetch(uCoarsest, ivec2(0), 0).g > 0.0 ? upsampled(uLevel1, p)
                                                          : uFallbackM;
}

#elif defined(LIGHT_EDGES)

layout(binding = 0) uniform sampler2D uColor; // linear RGB, float
layout(binding = 1) uniform sampler2D uDepth; // filled

// Rec. 709 luminance, summed in the CPU's order (blue first).
float luminance(vec3 rgb)
{
    return 0.0722 * rgb.b + 0.7152 * rgb.g + 0.2126 * rgb.r;
}

float luminanceAt(ivec2 texel)
{
    return luminance(texelFetch(uColor, texel, 0).rgb);
}

// The depth of the light whose brightest pixel is `at`: its own, unless it is the edge of a
// nearer, dim surface with the light beyond it (a neighbour above white and farther, the opposite
// one not above white and nearer than halfway); then the farthest such neighbour's, the first in
// row order on a tie (the CPU's rule, filter/DepthPrep.cpp).
float lightDepth(ivec2 at)
{
    const float own = texelFetch(uDepth, at, 0).r;
    float depth = own;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const ivec2 beyond = at + ivec2(dx, dy), opposite = at - ivec2(dx, dy);
            if ((dx == 0 && dy == 0) || any(lessThan(min(beyond, opposite), ivec2(0))) ||
                any(greaterThanEqual(max(beyond, opposite), uSize)))
                continue;
            const float far = texelFetch(uDepth, beyond, 0).r;
            if (far > depth && 2.0 * texelFetch(uDepth, opposite, 0).r <= own + far && luminanceAt(beyond) > 1.0 &&
                !(luminanceAt(opposite) > 1.0))
                depth = far;
        }
    return depth;
}

void main()
{
    const ivec2 p = ivec2(gl_FragCoord.xy);
    float z = texelFetch(uDepth, p, 0).r;
    const float brightness = luminance(texelFetch(uColor, p, 0).rgb);
    if (brightness > 1.0) {
        // The brightest pixel of the 3x3 neighbourhood, the first in row order on a tie.
        float brightest = brightness;
        ivec2 at = p;
        for (int y = max(p.y - 1, 0); y <= min(p.y + 1, uSize.y - 1); ++y)
            for (int x = max(p.x - 1, 0); x <= min(p.x + 1, uSize.x - 1); ++x) {
                const float b = luminance(texelFetch(uColor, ivec2(x, y), 0).rgb);
                if (b > brightest) {
                    brightest = b;
                    at = ivec2(x, y);
                }
            }
        z = lightDepth(at);
    }
    outDepth = z;
}

#endif
