#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// CoC pass (McIntosh et al. 2012, pass 1): linear colour in rgb, signed circle-of-confusion
// diameter in pixels in alpha (near < 0 < far), from the frame's colour and filled depth
// (coc_params.glsl).
//
// HALF_SIZE: the target is half the frame's size (Resolution::Half). Each texel takes the mean
// colour of a 2x2 block of the frame and the CoC of the block's sharpest pixel (smallest |CoC|),
// in pixels of the half-size image (half the frame's). A block across a depth edge then keeps
// the sharper side's size: a silhouette in focus stays in focus (and the upscale puts its pixels
// back), and the blend is not spread as far as the blurrier side would spread it. Measured on the
// Blender scene (rhombi-near, 6 taps, before the upscale prefilter was clamped): 33.10 dB,
// against 33.01 for the top-left pixel's CoC (the nearest-neighbour resize of the depth), 33.02
// for the nearest pixel's and 32.91 for the mean.
// The last row and column repeat on frames of odd size. QUARTER_SIZE: the same over 4x4 pixels
// (a quarter of the frame's size, CoC in quarter-size pixels), for frames whose blur is large
// and that have no sprites. HIGHLIGHTS (with highlightGain > 1, or bokeh sprites): the variant
// that treats highlights pixel by pixel before the mean, drawn only on the tiles that have
// highlights, over the plain variant's texels (CocPass). SPRITES (bokeh sprites,
// highlightThreshold > 0): a pixel's light above the threshold leaves the gather for its sprite,
// and a light in focus enters it as what lies round it; compiled out of the other variants, where
// llvmpipe would run it for every pixel.
#include "common.glsl"
#include "coc_params.glsl"
#include "highlights.glsl"

layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uColor; // sRGB8 textures decode to linear on fetch
layout(binding = 1) uniform sampler2D uDepth; // metres, holes already filled
layout(binding = 2) uniform sampler2D uColorSmooth; // uColor, filtered

// The bokeh sprites' count (highlight_sprites.comp, run before this pass): their light leaves
// the gather only if the frame's sprites fit its budget and are drawn.
layout(std430, binding = 2) readonly buffer SpriteCount {
    uint spriteHeader[8]; // ..., [4] the budget, [5] the pixels that make a sprite
};

// Colour (highlights recovered, sanitised, the sprites' share taken out) and CoC of one pixel of
// the frame.
vec4 pixel(ivec2 texel)
{
    const vec3 raw = texelFetch(uColor, texel, 0).rgb;
#ifdef SPRITES
    const float coc = signedCoc(texelFetch(uDepth, texel, 0).r);
    const vec3 color = blurColor(raw, coc);
    const bool drawn = spriteHeader[5] <= spriteHeader[4];
    // A light in focus goes into the blur as what lies round it (standIn(), highlights.glsl). In
    // a half-size block's mean and in the bilinear taps of the blur around it, its HDR value took
    // the background's CoC and lit the background's blur, a halo as large as that blur (3.9-4.3 %
    // of such a light outside its own pixels at half size; 1.0-1.4 % with the light at white's
    // worth; none with the stand-in), and the upscale's frame + bil(R - C) drew its block square.
    // The light keeps its brightness: InFocusLightPass adds the rest back after the blur, by the
    // share of the pixel no blurred foreground covers (in_focus_light.frag; at half size the
    // upscale keeps the stand-in for it). The corpus (docs/accuracy.md): railing-lights 28.14 ->
    // 31.78 dB balanced with white's worth, 32.15 with the stand-in; tele-135-f8 39.64 -> 40.99.
    if (abs(coc) < 1.0)
        return vec4(standIn(uColor, texel, color), coc);
    return vec4(drawn ? color * spriteShare(color, coc, texel, textureSize(uColor, 0)) : color, coc);
#else
    const float coc = signedCoc(texelFetch(uDepth, texel, 0).r);
    return vec4(blurColor(raw, coc), coc);
#endif
}

// The CoC of the four with the smallest |CoC|.
float sharpest(vec4 c)
{
    const float c01 = abs(c.x) <= abs(c.y) ? c.x : c.y;
    const float c23 = abs(c.z) <= abs(c.w) ? c.z : c.w;
    return abs(c01) <= abs(c23) ? c01 : c23;
}

#ifdef HALF_SIZE
// A half-size texel on the frame's border holds the colour of the frame's border pixels of its
// block only (the first or last row, column or corner), not the whole 2x2 block's mean. The
// blurs read past the frame's edge the edge texels repeated (the samplers clamp), as at full size
// they repeat the frame's edge pixels; a block's mean there brought the row inside it out past
// the edge too: a light band along the frame's top edge (overlapping-lights' mortar line, half
// of whose bricks lie above the frame) came out at the block's half, and 49 % of that scene's
// squared error lay in its top 8 rows. Its CoC stays the block's (the gather below).
// The corners of the block `a`..`b` of the texel: moved onto the border row and column.
ivec2 edgeLow(ivec2 texel, ivec2 a, ivec2 b)
{
    const ivec2 lastTexel = (textureSize(uColor, 0) + 1) / 2 - 1;
    return ivec2(texel.x == lastTexel.x ? b.x : a.x, texel.y == lastTexel.y ? b.y : a.y);
}
ivec2 edgeHigh(ivec2 texel, ivec2 a, ivec2 b)
{
    return ivec2(texel.x == 0 ? a.x : b.x, texel.y == 0 ? a.y : b.y);
}
#endif

void main()
{
    const ivec2 texel = ivec2(gl_FragCoord.xy);
#if defined(QUARTER_SIZE) && defined(HIGHLIGHTS)
    const ivec2 last = textureSize(uColor, 0) - 1;
    vec3 sum = vec3(0.0);
    float coc = 3.4e38;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            const vec4 p = pixel(min(4 * texel + ivec2(i, j), last));
            sum += p.rgb;
            coc = abs(p.a) < abs(coc) ? p.a : coc;
        }
    outColor = vec4(sum * (1.0 / 16.0), 0.25 * coc);
#elif defined(QUARTER_SIZE)
    // Four bilinear fetches at the corners between 2x2 blocks, four gathers of their depths.
    // A block past the frame's last row or column repeats it (the samplers clamp), as the
    // half-size pass does.
    const vec2 size = vec2(textureSize(uColor, 0));
    vec3 sum = vec3(0.0);
    float coc = 3.4e38;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const vec2 uv = vec2(4 * texel + 2 * ivec2(i, j) + 1) / size;
            const vec4 z = textureGather(uDepth, uv, 0);
            const float c = sharpest(vec4(signedCoc(z.x), signedCoc(z.y), signedCoc(z.z), signedCoc(z.w)));
            coc = abs(c) < abs(coc) ? c : coc;
            sum += textureLod(uColorSmooth, uv, 0.0).rgb;
        }
    outColor = vec4(sanitizeColor(0.25 * sum, largestColor), 0.25 * coc);
#elif defined(HALF_SIZE) && defined(HIGHLIGHTS)
    // Highlight recovery needs each pixel's own colour and CoC. On the frame's border, the
    // colour of the border's pixels only (edgeLow()).
    const ivec2 last = textureSize(uColor, 0) - 1;
    const ivec2 a = 2 * texel, b = min(a + 1, last);
    const vec4 p0 = pixel(a), p1 = pixel(ivec2(b.x, a.y)), p2 = pixel(ivec2(a.x, b.y)), p3 = pixel(b);
    vec3 sum = p0.rgb + p1.rgb + p2.rgb + p3.rgb;
    const ivec2 lo = edgeLow(texel, a, b), hi = edgeHigh(texel, a, b);
    if (lo != a || hi != b)
        sum = pixel(lo).rgb + pixel(ivec2(hi.x, lo.y)).rgb + pixel(ivec2(lo.x, hi.y)).rgb + pixel(hi).rgb;
    outColor = vec4(0.25 * sum, 0.5 * sharpest(vec4(p0.a, p1.a, p2.a, p3.a)));
#elif defined(HALF_SIZE)
    // One bilinear fetch at the block's corner is the mean of its colours (sRGB decoded before
    // filtering), one gather its four depths: 1.3 instead of 3.7 ms on llvmpipe at 640x480.
    // Sanitised after the mean: a NaN or Inf pixel takes its block with it (to 0 or the largest
    // colour), where the frame-sized pass loses only the pixel. On the frame's border, the
    // colour of the border's pixels only (edgeLow()): the fetch at their centre line.
    const vec2 size = vec2(textureSize(uColor, 0));
    const vec2 uv = vec2(2 * texel + 1) / size;
    const vec4 z = textureGather(uDepth, uv, 0);
    const vec4 c = vec4(signedCoc(z.x), signedCoc(z.y), signedCoc(z.z), signedCoc(z.w));
    const ivec2 a = 2 * texel, b = min(a + 1, textureSize(uColor, 0) - 1);
    const vec2 colorUv = (vec2(edgeLow(texel, a, b) + edgeHigh(texel, a, b)) * 0.5 + 0.5) / size;
    outColor = vec4(sanitizeColor(textureLod(uColorSmooth, colorUv, 0.0).rgb, largestColor), 0.5 * sharpest(c));
#else
    outColor = pixel(texel);
#endif
}
