#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Energy-conserving hexagon from three one-sided rhombi. A regular hexagon of circumradius R is
// the union of three rhombi that share its centre, each spanned by two of the three unit vectors
// u1, u2, u3 (120 deg apart, towards alternate corners), and each rhombus is the convolution of
// two one-sided segments [0, R]·ui. With L_i the mean along [0, R]·u_i:
//
//   hexagon = (L1 L2 + L2 L3 + L3 L1) / 3 = (L2 (L1 s) + L3 (L1 s) + L3 (L2 s)) / 3
//
//   pass 1 (FIRST): X = L1 s, Z = L2 s                       -> two targets
//   pass 2:         A = L2 X, B = (L3 X + L3 Z) / 2          -> two targets
//   composite:      (A + 2 B) / 3
//
// L3 runs over X and over Z apart, not once over their mean as first written: only the third
// rhombus (L3 Z, both lines off the axes with a corner on top) needs the pair of taps that
// softens its edges; L3 X keeps the sharper taps of a line crossing an axis line (+0.11 dB on
// the Blender scene at full size, +0.14 at half, for a third line read in pass 2).
//
// Unlike the min() of McIntosh et al. 2012 (hex_blur.frag), the kernel is flat: a highlight
// keeps all of its energy and texture is not darkened. Each line reads half the distance of a
// centred segment, so the same tap spacing takes half the taps. The sign convention follows
// hex_blur.frag: a counter-clockwise screen angle moves towards smaller v.
//
// Nearer or farther: signed CoC grows with depth through the focus plane (both CoC models), so
// comparing the taps' CoC orders them as depth would, without a depth fetch per tap.
//
// Bleeding: a tap nearer than the centre and sharper than it is weighted by its blurriness as in
// the paper (bleedingBias/bleedingMult); such a tap above white counts by white's worth of its
// light, and a nearer tap whose own blur does not reach the centre not at all (no ghost of a
// light in front, no halo of a sharper object over a blurrier background). NEAR_FIELD, "scatter as gather" (Jimenez 2014): each line reaches as far as the
// largest foreground blur that can reach this pixel (tile maxima dilated on the CPU); a nearer
// tap that is blurrier than the centre counts where its own radius reaches the centre, with the
// coverage a scattered segment of its length would give, and lies over the centre's own blur by
// that coverage.
//
// What a blurred object hides: a farther, sharper tap whose own blur does not reach the centre
// lies behind the centre's blur, in the share of its piece the tap does not reach (as for nearer
// taps). A real lens sees around the object there, and what it sees is hidden in the frame; the
// visible background nearest the object is the best guess of it (a railing's bars over a lit
// wall: the wall's lines run on behind the bars), not the mean of everything the centre's blur
// spans (the wall blurred by the bars' blur, a notch in every line). So the hidden share of a
// line takes the colour of its hidden taps weighted by BEHIND_FADE^(n-1), n counting them from
// the object outwards. Pass 2's taps are pass-1 means that already hold the foreground's spread
// and the object's antialiased edge near it, so its fade is gentler: the corpus measured 0.7
// there free of any loss, 0.5 and less losing up to 0.36 dB where a large object's edge meets a
// brighter background (docs/accuracy.md, "What each improvement bought").
// In pass 1 the hidden share takes instead, where the lines saw the background, the background
// interpolated across the object at the pixel itself (hiddenBackground()), not where a line
// leaves the object: the lines off the vertical run 30 deg below the horizontal and meet the
// background beside a vertical object lower than the pixel by up to tan(30 deg) of its width,
// and a line leaving a horizontal object upwards sees only what lies above it.
//
// FIRST_PASS and NEAR_FIELD are compile-time
// variants: llvmpipe pays for every instruction of a branch on a uniform. FUSED (second pass
// only) writes the composite (A + 2B) / 3 itself, to one target: the output.
#include "common.glsl"
#include "rhombus_lines.glsl"

#ifdef FIRST_PASS
const float BEHIND_FADE = 0.5;
#else
const float BEHIND_FADE = 0.7;
#endif

layout(location = 0) out vec4 outFirst;
#ifndef FUSED
layout(location = 1) out vec4 outSecond;
#endif

// Each line reads its texture through two units: unfiltered and bilinear.
layout(binding = 0) uniform sampler2D uLine1;        // pass 1: rgb + signed CoC (px); pass 2: X
layout(binding = 1) uniform sampler2D uLine1Smooth;
layout(binding = 2) uniform sampler2D uNearDiameter; // per tile, pixels (NEAR_FIELD only)
layout(binding = 3) uniform sampler2D uLine2;        // pass 1: the CoC target again; pass 2: Z
layout(binding = 4) uniform sampler2D uLine2Smooth;

layout(std140, binding = 0) uniform RhombusBlurParams {
    vec4 directions;       // xy, zw: texture-space offset per pixel along this pass's two lines
    vec4 across;           // pass 2: texture-space offset half a pixel across each line, or 0
    vec2 baseSteps;        // pixels: the step of each line that moves one pixel on its major axis
    int nearTileSize;      // pixels per tile of uNearDiameter
    float bleedingBias;    // the paper's unit: CoC as a fraction of the image height
    float bleedingMult;
    float cocToPaperUnits; // 1 / image height in pixels
    float bleedingRamp;    // width of the bleeding rule's fade, the paper's unit
};

// The mean along a one-sided segment of length `extent` from this pixel in `direction`, in
// pieces one step long: the centre covers [0, 1/2], tap k >= 1 covers [k - 1/2, k + 1/2] steps,
// and the last piece counts by the part of it inside the segment. The base step moves exactly one
// pixel along the line's major axis (baseStep = 1 / max(|cos|, |sin|) pixels), so successive taps
// sit in successive columns (or rows). A segment shorter than half a step is the centre alone
// (|CoC| < 1 px leaves a pixel as it is), and the result moves continuously with the CoC: taps
// sit at fixed offsets and only their weights change. Lines longer than maxTaps base steps space
// the taps out; those taps move with the CoC and are always filtered (the `smooth` samplers;
// rhombus_lines.glsl has how each line takes its taps).
// One line, or with `both` two lines along the same direction over two sources whose texels
// carry the same CoC (pass 2's u3 over X and over Z): the taps' weights come from the first
// source's CoC and serve both, so the second costs only its fetches.
// The pixel centre in texture coordinates, from gl_FragCoord: an interpolated uv rounds
// differently on the tiles (tiles.vert) than on the full-screen triangle, which moved taps by an
// ulp and outputs by an 8-bit step between the plan and every pass on every pixel.
vec2 pixelUv()
{
    return gl_FragCoord.xy / vec2(textureSize(uLine1, 0));
}

// The background behind a pixel: farther, and at most half as blurred.
const float BEHIND_SHARPER = 2.0;
bool behindCenter(vec4 tap, vec4 center)
{
    return tap.a > center.a && abs(tap.a) * BEHIND_SHARPER < abs(center.a);
}

#ifdef FIRST_PASS
// What lies behind this pixel where it is part of a blurred object: the background seen beside
// the object, interpolated across it at the pixel. Its row and its column each look for the
// background (behindCenter()) to either side, as far as the pixel's own blur reaches and at most
// CROSSING_TAPS texels. One that finds it on both sides interpolates linearly between them at
// this pixel; one that finds it on one side only takes that side's colour and counts three times
// as long (the other side may lie just beyond the search). The two are mixed by their length^-4,
// so that the shorter crossing rules without a switch between neighbouring pixels (the shorter
// alone left speckles along a sphere's silhouette on the Blender scene). On each side the pixel
// after the first found is taken where it is background too: the first is often the object's
// antialiased edge, whose colour holds some of the object and whose depth (not antialiased) the
// background's. The diagonals as two more crossings measured the same on the corpus, at twice
// the search's cost. a = 0: none found, and the lines' own estimate stays.
const int CROSSING_TAPS = 8;

// One side of a crossing: the step the background was first found at (0: not yet), its colour,
// and whether the next step may still replace it (the pixel after the first found).
struct CrossingSide {
    float found;
    vec3 color;
    bool pending;
};

void crossingStep(inout CrossingSide side, ivec2 at, vec4 center, int k)
{
    const vec4 tap = texelFetch(uLine1, clamp(at, ivec2(0), textureSize(uLine1, 0) - 1), 0);
    const bool background = behindCenter(tap, center);
    if (side.found == 0.0) {
        if (background) {
            side.found = float(k);
            side.color = tap.rgb;
            side.pending = true;
        }
    } else if (side.pending) {
        if (background)
            side.color = tap.rgb;
        side.pending = false;
    }
}

vec4 hiddenBackground(vec4 center)
{
    const ivec2 texel = ivec2(gl_FragCoord.xy);
    // One step past the pixel's own blur, for the pixel after the first found. Not a compile-time
    // count, so that the loop is not unrolled and ends once every pixel shaded together is done.
    const int steps = min(CROSSING_TAPS, int(ceil(0.5 * abs(center.a)))) + 1;
    vec3 sum = vec3(0.0);
    float weights = 0.0;
    for (int d = 0; d < 2; ++d) {
        const ivec2 offset = d == 0 ? ivec2(1, 0) : ivec2(0, 1);
        CrossingSide after = CrossingSide(0.0, vec3(0.0), false), before = after;
        for (int k = 1; k <= steps; ++k) {
            if (after.found > 0.0 && before.found > 0.0 && !after.pending && !before.pending)
                break;
            crossingStep(after, texel + offset * k, center, k);
            crossingStep(before, texel - offset * k, center, k);
        }
        if (after.found == 0.0 && before.found == 0.0)
            continue;
        const bool both = after.found > 0.0 && before.found > 0.0;
        const vec3 color = both ? (after.color * before.found + before.color * after.found) / (after.found + before.found)
                                : (after.found > 0.0 ? after.color : before.color);
        const float span = both ? after.found + before.found : 3.0 * max(after.found, before.found);
        const float weight = 1.0 / (span * span * span * span);
        sum += color * weight;
        weights += weight;
    }
    return weights > 0.0 ? vec4(sum / weights, 1.0) : vec4(0.0);
}
#endif

// A line's result with another colour c for its hidden share: front + back (visible + share
// (c - visible)), with front its foreground's part (alpha times the foreground's colour), back
// the background's share (1 - alpha), visible the mean of its taps not hidden and share the
// hidden share of the background. In that form a flat colour stays exactly itself, and beside a
// light of 1e36 nothing cancels to below zero (result + share (c - the hidden share's colour)
// did: HardCasesGLTest).
struct Hidden {
    vec3 front;
    float back;
    vec3 visible;
    float share;
};

vec3 withHidden(Hidden h, vec3 c)
{
    return h.front + h.back * (h.visible + h.share * (c - h.visible));
}

void lines(sampler2D source, sampler2D smoothSource, const int mode, sampler2D source2, sampler2D smoothSource2,
           const int mode2, const bool both, vec2 direction, float baseStep, vec2 across, vec4 center, vec3 center2,
           float extent, out vec3 result, out vec3 result2, out Hidden hiddenPart)
{
    const vec2 uv = pixelUv();
    const float radius = 0.5 * abs(center.a);
    const float centerBlur = abs(center.a) * cocToPaperUnits;
    const LineSteps steps = lineSteps(baseStep, extent, float(MAX_TAPS));
    const float step = steps.step;
    const float length = steps.length;       // in steps
    const float ownLength = radius / step;   // the centre's own blur, in steps
    const float halfPerStep = 0.5 / step;    // a CoC diameter to a radius in steps
    const int taps = steps.taps;             // pieces k >= 1 that start inside the segment
    const float smoothing = steps.smoothing; // spread taps leave the lattice and are filtered

    float backgroundWeight = min(ownLength, 0.5);
    vec3 background = center.rgb * backgroundWeight;
    vec3 background2 = center2 * backgroundWeight;
#ifdef NEAR_FIELD
    vec3 foreground = vec3(0.0), foreground2 = vec3(0.0);
    float coverage = 0.0;
#endif
    vec3 behind = vec3(0.0), behind2 = vec3(0.0); // the hidden share's colour, faded outwards
    float behindWeight = 0.0, behindNorm = 0.0, fade = 1.0;
    bool sawBackground = false; // a hidden tap that is the background behind the centre
    // UNROLLED: MAX_TAPS is a compile-time constant, so the compiler unrolls the loop, and
    // llvmpipe then runs every tap for every pixel (masked); the plain loop runs only as many as
    // the longest line among the pixels it shades together, with a loop's overhead per tap. The
    // plan takes the unrolled form where most lines run to MAX_TAPS anyway (Pipeline.cpp).
#ifdef UNROLLED
    for (int k = 1; k <= MAX_TAPS; ++k) {
        if (k > taps)
            break;
#else
    for (int k = 1; k <= taps; ++k) {
#endif
        const float distance = float(k) * step;
        const vec2 coords = uv + direction * distance;
        const vec4 tap = fetchTap(source, smoothSource, mode, coords, across, smoothing);
        const vec3 tap2 = both ? fetchTap(source2, smoothSource2, mode2, coords, across, smoothing).rgb : vec3(0.0);
        const bool nearer = tap.a < center.a;
        const float tapBlur = abs(tap.a) * cocToPaperUnits;
        // The centre's own blur, with the paper's bleeding rule, faded in over a bleedingRamp
        // around its threshold instead of switched: depth noise at the threshold would make the
        // pixel flicker (a tap may carry most of a short line's weight).
        const float rule = nearer ? clamp(tapBlur * bleedingMult, 0.0, 1.0) : 1.0;
        const float bleeding = clamp((centerBlur - tapBlur - bleedingBias) / bleedingRamp + 0.5, 0.0, 1.0);
        float weight = mix(1.0, rule, bleeding);
        // A nearer tap above white lights this pixel by at most white's worth of it where the
        // bleeding rule weighs it (a share of its weight inversely proportional to its
        // luminance). A nearer tap whose own blur does not reach this pixel does not light it at
        // all: there it hides what lies behind it (weights, not colours, change, so the output
        // stays a mean of the frame's colours). Otherwise a nearer, sharper object was drawn a
        // second time, as a pale copy as large as the background's blur: in focus or just in
        // front of it (the bleeding rule's fallback weight, or its full weight below the rule's
        // bias), or at the edge of its own bokeh. This held first for taps above white only
        // (fading in from 1 to 2 times white); but where a light makes bokeh sprites the gather
        // keeps white's worth of it, below the fade, so its halo came back, twice as wide as
        // its own blur round the large lights of spheres-near-focus. For every tap, the corpus'
        // median rose 2.2 dB (docs/accuracy.md, "What each improvement bought").
        const float ownPiece = clamp(ownLength - float(k) + 0.5, 0.0, 1.0);
        const float tapPiece = clamp(abs(tap.a) * halfPerStep - float(k) + 0.5, 0.0, 1.0);
        const float unreached = nearer ? clamp(1.0 - tapPiece / max(ownPiece, 1e-6), 0.0, 1.0) : 0.0;
        const float tapLuminance = luminance(tap.rgb);
        weight *= mix(1.0, 1.0 / max(tapLuminance, 1.0), nearer ? bleeding : 0.0);
        weight *= 1.0 - unreached;
        weight *= ownPiece;
#ifdef NEAR_FIELD
        const float reach = foregroundReach(tap.a, center.a, radius, distance, float(k), length);
        const float share = foregroundShare(reach, tap.a, step);
        foreground += tap.rgb * share;
        foreground2 += tap2 * share;
        coverage += share;
        weight *= 1.0 - reach;
#endif
        const float hidden = nearer ? 0.0 : clamp(1.0 - tapPiece / max(ownPiece, 1e-6), 0.0, 1.0);
        const float hiddenWeight = weight * hidden;
        sawBackground = sawBackground || (hiddenWeight > 0.0 && behindCenter(tap, center));
        weight -= hiddenWeight;
        behindWeight += hiddenWeight;
        behind += tap.rgb * (hiddenWeight * fade);
        behind2 += tap2 * (hiddenWeight * fade);
        behindNorm += hiddenWeight * fade;
        fade *= mix(1.0, BEHIND_FADE, hidden);
        background += tap.rgb * weight;
        background2 += tap2 * weight;
        backgroundWeight += weight;
    }
    // The taps' own colours without the hidden share, and their weight.
    const vec3 visible = background;
    const float visibleWeight = backgroundWeight;
    if (behindNorm > 0.0) {
        // The mean first: a flat colour stays exactly itself.
        background += (behind / behindNorm) * behindWeight;
        background2 += (behind2 / behindNorm) * behindWeight;
        backgroundWeight += behindWeight;
    }
    // The bleeding rule may reject every tap: the centre stays (its weight is > 0 whenever the
    // centre has a blur of its own; without one, the background is the centre).
    const bool kept = backgroundWeight > 0.0;
    background = kept ? background / backgroundWeight : center.rgb;
    background2 = kept ? background2 / backgroundWeight : center2;
    // What the result is with another colour for the hidden share (Hidden). Only where the line
    // saw the background behind the centre: a hidden share from a receding surface (each tap a
    // little farther and sharper) has none to find, and a search for it would only cost.
    hiddenPart.visible = visibleWeight > 0.0 ? visible / visibleWeight : center.rgb;
    hiddenPart.share = kept && sawBackground ? behindWeight / backgroundWeight : 0.0;
    hiddenPart.front = vec3(0.0);
    hiddenPart.back = 1.0;
#ifdef NEAR_FIELD
    const float alpha = clamp(coverage, 0.0, 1.0);
    result = alpha * (foreground / max(coverage, 1e-6)) + (1.0 - alpha) * background;
    result2 = alpha * (foreground2 / max(coverage, 1e-6)) + (1.0 - alpha) * background2;
    hiddenPart.front = alpha * (foreground / max(coverage, 1e-6));
    hiddenPart.back = 1.0 - alpha;
#else
    result = background;
    result2 = background2;
#endif
}

vec3 line(sampler2D source, sampler2D smoothSource, const int mode, vec2 direction, float baseStep, vec2 across,
          vec4 center, float extent, out Hidden hiddenPart)
{
    vec3 result, unused;
    lines(source, smoothSource, mode, source, smoothSource, mode, false, direction, baseStep, across, center, vec3(0.0),
          extent, result, unused, hiddenPart);
    return result;
}

void main()
{
    const ivec2 texel = ivec2(gl_FragCoord.xy);
    const vec4 center = texelFetch(uLine1, texel, 0);
    float extent = 0.5 * abs(center.a);
#ifdef NEAR_FIELD
    extent = max(extent, 0.5 * texelFetch(uNearDiameter, texel / nearTileSize, 0).r);
#endif
#ifdef FIRST_PASS
    const vec4 centerB = center;
#else
    const vec4 centerB = texelFetch(uLine2, texel, 0);
#endif
    // In focus (|CoC| < 1 px) and out of any foreground's reach: the pixel stays, bit-exact.
    if (extent < 0.5) {
#ifdef FUSED
        outFirst = vec4(center.rgb, 1.0);
#else
        outFirst = center;
        outSecond = centerB;
#endif
        return;
    }
    Hidden hiddenX, hiddenZ;
#ifdef FIRST_PASS
    vec3 x = line(uLine1, uLine1Smooth, LINE1_MODE, directions.xy, baseSteps.x, across.xy, center, extent, hiddenX);
    vec3 z = line(uLine2, uLine2Smooth, LINE2_MODE, directions.zw, baseSteps.y, across.zw, center, extent, hiddenZ);
    // Only pixels whose lines have a hidden share look for the background behind them (most have
    // none: a GPU skips the search where no pixel of a group needs it).
    if (hiddenX.share > 0.0 || hiddenZ.share > 0.0) {
        const vec4 behind = hiddenBackground(center);
        if (behind.a > 0.0) {
            x = hiddenX.share > 0.0 ? withHidden(hiddenX, behind.rgb) : x;
            z = hiddenZ.share > 0.0 ? withHidden(hiddenZ, behind.rgb) : z;
        }
    }
    outFirst = vec4(x, center.a);
    outSecond = vec4(z, center.a);
#else
    // Pass 2's hidden share keeps its lines' own estimate. Its taps are pass-1 means, which
    // beside a blurred object hold the object's spread; the same search over them, or over the
    // CoC target, measured lower on the corpus (near-object 1.0-1.6 dB, railing-lights itself
    // 0.1-0.15 dB; docs/accuracy.md).
    const vec3 a = line(uLine1, uLine1Smooth, LINE1_MODE, directions.xy, baseSteps.x, across.xy, center, extent,
                        hiddenX);
    vec3 b1, b2;
    lines(uLine1, uLine1Smooth, LINE3_MODE, uLine2, uLine2Smooth, LINE2_MODE, true, directions.zw, baseSteps.y,
          across.zw, center, centerB.rgb, extent, b1, b2, hiddenZ);
    const vec3 b = 0.5 * (b1 + b2);
#ifdef FUSED
    // The composite in the same pass, straight into the output (composite.frag's SUM formula).
    outFirst = vec4(b + (a - b) * (1.0 / 3.0), 1.0);
#else
    outFirst = vec4(a, center.a);
    outSecond = vec4(b, center.a);
#endif
#endif
}
