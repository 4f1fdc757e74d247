// SPDX-License-Identifier: LGPL-2.1-or-later
// Highlights, shared by the CoC pass (coc.frag) and the bokeh sprites (highlight_sprites.comp);
// needs coc_params.glsl and common.glsl.

// Highlights from 8-bit video: a light clipped at 255 is far brighter than 1.0, and a
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

// A pixel's colour as the blur sees it: highlights recovered, sanitised.
vec3 blurColor(vec3 color, float coc)
{
    return sanitizeColor(recoverHighlight(color, coc), largestColor);
}

// What a pixel in focus (|CoC| < 1 px) of `colors` enters the blur as, on frames with bokeh
// sprites (coc.frag; upscale.frag and in_focus_light.frag take the same): itself, or if it is a
// light (luminance above the threshold) a stand-in: the mean of the pixels round it, 4 px away,
// that are not above the threshold (what lies behind the light), or, where none is, the light
// scaled to the threshold's luminance. At white's worth instead (the light scaled everywhere),
// its bilinear taps still left 1.0-1.4 % of it in the blur of the background round it, a faint
// disc (HighlightSpritesGLTest).
vec3 standIn(sampler2D colors, ivec2 texel, vec3 color)
{
    if (luminance(color) <= highlightThreshold)
        return color;
    const ivec2 last = textureSize(colors, 0) - 1;
    const ivec2 ring[8] = ivec2[8](ivec2(4, 0), ivec2(-4, 0), ivec2(0, 4), ivec2(0, -4), ivec2(3, 3), ivec2(-3, 3),
                                   ivec2(3, -3), ivec2(-3, -3));
    vec3 sum = vec3(0.0);
    float count = 0.0;
    for (int i = 0; i < 8; ++i) {
        const vec3 c = sanitizeColor(texelFetch(colors, clamp(texel + ring[i], ivec2(0), last), 0).rgb, largestColor);
        const bool dark = luminance(c) <= highlightThreshold;
        sum += dark ? c : vec3(0.0);
        count += dark ? 1.0 : 0.0;
    }
    return count > 0.0 ? sum / count : color * min(1.0, highlightThreshold / max(luminance(color), 1e-6));
}

// The neighbourhood a light is judged in: the 3x3 tiles of 16x16 px around the pixel's own
// (48x48 px), clamped to the frame, summed on the CPU (SceneAnalysis::tileNeighbourhood): their
// pixels, how many of them are above white, their luminance summed. One tile was too small for
// the lights of the accuracy corpus: a light 10-15 px across fills most of its tile, and 64-84 %
// of those scenes' light above white made no sprite (docs/accuracy.md).
layout(std430, binding = 1) readonly buffer TileNeighbourhoods {
    vec4 tileNeighbourhood[]; // rows of tiles top to bottom: pixels, highlights, luminance, 0
};

const int kTileSize = 16; // SceneAnalysis::kTileSize

struct Neighbourhood {
    float pixels;     // pixels in the tiles
    float highlights; // of them above white
    float luminance;  // their luminance summed
};

Neighbourhood neighbourhood(ivec2 texel, ivec2 frameSize)
{
    const int tilesX = (frameSize.x + kTileSize - 1) / kTileSize;
    const vec4 n = tileNeighbourhood[(texel.y / kTileSize) * tilesX + texel.x / kTileSize];
    return Neighbourhood(n.x, n.y, n.z);
}

// A neighbourhood's pixels become sprites only where at most this share of them is above white:
// lights rather than a bright surface or texture (a checkered wall in HDR made 38 % of a frame's
// pixels sprites, 500 ms of drawing per frame; the frame's budget, HighlightSpritePass, bounds
// that too). A quarter left the larger lights of the corpus' spheres scenes (30 % of the 48 x 48
// px around them) to the gather, which brings a nearer, sharper light only by white's worth past
// its edge: spheres-far-focus measured 32.85 against 38.74 dB (balanced), spheres-near-focus
// 29.71 against 31.99; 0.4 and 0.5 measured the same on every scene.
const float kMostSpritePixels = 0.4;

// A sprite is drawn only for a pixel more than this many times as bright as its neighbourhood's
// mean: a light stands out of its surroundings, where a bright region (a sky, a lamp's shade) is
// spread as well by the gather, and sprites for all of its pixels would cost the draw one
// hexagon each.
const float kSpriteAboveMean = 1.5;

// A sprite is drawn only if it puts at least this much luminance on each pixel it covers: on the
// Blender scene, 279 of 2683 pixels above white carry 98.9 % of the light above it; the others,
// most of them a little above white on large near blur, would cost the draw ten times as much
// for light the gather spreads as well.
const float kSpriteLightPerPixel = 1.0 / 1024.0;

// The share of a blurred pixel's colour that the gather keeps if the pixel makes a sprite: all
// of it up to a luminance of highlightThreshold, and that much of a brighter one, whose rest a
// bokeh sprite scatters with the hexagon's exact edges (highlight_sprite.frag). 1 for pixels
// that make none. (The frame's sprites are drawn only if they fit the budget: coc.frag.)
float spriteShare(vec3 color, float coc, ivec2 texel, ivec2 frameSize)
{
    if (highlightThreshold <= 0.0 || abs(coc) < 1.0)
        return 1.0;
    const float brightness = luminance(color);
    const float radius = 0.5 * abs(coc);
    const float area = 2.598076 * radius * radius; // the hexagon's, 3 sqrt(3) / 2 R^2
    if (brightness - highlightThreshold < kSpriteLightPerPixel * area)
        return 1.0;
    const Neighbourhood n = neighbourhood(texel, frameSize);
    return brightness * n.pixels > kSpriteAboveMean * n.luminance &&
                   n.highlights <= kMostSpritePixels * n.pixels
               ? highlightThreshold / brightness
               : 1.0;
}
