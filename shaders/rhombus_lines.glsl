// SPDX-License-Identifier: LGPL-2.1-or-later
// The rhombus blur's lines (rhombus_blur.frag): how a tap is fetched, and the share of a pixel
// that a nearer, blurrier tap covers. Shared with in_focus_light.frag, which weighs what it puts
// back by the same coverage. Included, so no #version here.

// Unfiltered taps off the axes make digital lines, and a second line off the axes crossing a
// digital line hits it twice or never: a point light's hexagon came out striped. Lines that are
// crossed that way later, and lines that cross them, take bilinear taps. Bilinear taps do not
// cure it where both lines are off the axes (the third rhombus, u3 of u2): crossing a bilinear
// line obliquely still depends on where it lies between texel centres (+-44 % on a point light,
// measured with a CPU model of this shader). A pass-2 line over a pass-1 line, both off the axes
// (PAIR), takes each tap as the mean of two, half a pixel to either side of it: +-8 %.
// `mode` is a compile-time constant per line (LINE1_MODE to LINE3_MODE, set by RhombusBlurPass):
// llvmpipe runs both sides of a branch that differs between pixels, so a run-time choice cost
// every tap all of its fetches.
const int POINT = 0;  // unfiltered (bilinear only for spread taps)
const int SMOOTH = 1; // bilinear
const int PAIR = 2;   // two bilinear taps, `across` to either side
vec4 fetchTap(sampler2D source, sampler2D smoothSource, const int mode, vec2 coords, vec2 across, float smoothing)
{
    if (mode == PAIR)
        return 0.5 * (textureLod(smoothSource, coords + across, 0.0) + textureLod(smoothSource, coords - across, 0.0));
    if (mode == SMOOTH)
        return textureLod(smoothSource, coords, 0.0);
    vec4 tap = textureLod(source, coords, 0.0);
    if (smoothing > 0.0)
        tap = mix(tap, textureLod(smoothSource, coords, 0.0), smoothing);
    return tap;
}

// How a line of length `extent` (pixels) is stepped, at most `maxTaps` taps: the base step, or
// longer where the line needs more taps than that; its length in steps; the taps k >= 1 whose
// pieces start inside it; and how far the spread taps have left the lattice (filtered taps fade
// in over the first quarter of a step, so that the output stays continuous in the CoC).
struct LineSteps {
    float step;
    float length;
    int taps;
    float smoothing;
};
LineSteps lineSteps(float baseStep, float extent, float maxTaps)
{
    LineSteps s;
    s.step = max(baseStep, extent / maxTaps);
    s.length = extent / s.step;
    s.taps = int(ceil(s.length - 0.5));
    s.smoothing = clamp((s.step / baseStep - 1.0) * 4.0, 0.0, 1.0);
    return s;
}

// NEAR_FIELD, "scatter as gather" (Jimenez 2014): how far a nearer tap blurrier than this pixel
// reaches it, tap k (`distance` pixels away) of a line `length` steps long: soft over the last
// half pixel of the tap's radius.
float foregroundReach(float tapCoc, float centerCoc, float radius, float distance, float k, float length)
{
    const float tapRadius = 0.5 * abs(tapCoc);
    return tapCoc < centerCoc && tapRadius > radius
               ? clamp(tapRadius - distance + 0.5, 0.0, 1.0) * clamp(length - k + 0.5, 0.0, 1.0)
               : 0.0;
}

// The share of this pixel such a tap covers: a segment of length tapRadius scattered from the
// tap puts step / tapRadius of it here.
float foregroundShare(float reach, float tapCoc, float step)
{
    return reach * step / max(0.5 * abs(tapCoc), 1e-3);
}
