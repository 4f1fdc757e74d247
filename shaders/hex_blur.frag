#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// One directional blur of McIntosh, Riecke & DiPaola 2012, "Efficiently Simulating the Bokeh of
// Polygonal Apertures in a Post-Process Depth of Field Shader". Run at 0 deg on the CoC pass,
// then at +120 and -120 deg on that result; min() of the two is a hexagon:
//
//   pass 0 deg      +120 deg of it     -120 deg of it     min(A, B)
//    ______           ______            ______             ____
//                    /     /            \     \           /    \
//                   /_____/              \_____\          \____/
//
// Each pass averages `sampleCount` taps on a segment as long as the centre's CoC diameter.
// The paper's bleeding fix: a tap nearer than the centre and sharper than it (by more than
// bleedingBias) is weighted by its own blurriness * bleedingMult, so sharp foreground does not
// smear onto a blurry background; blurriness is in the paper's unit, a fraction of image height.
//
// The CoC the chain blurs by is the paper's: a diameter, never negative. The CoC pass keeps the
// sign (near < 0 < far) for the rest of the project (the near-field layer, the rhombi, the coc
// view); here every tap's CoC is taken as |CoC| (bilinear over the four texels' |CoC|, so a tap
// that straddles near and far blur does not average them towards 0), and each pass writes the
// weighted mean of |CoC| to alpha, as the paper's blurred alpha. Nearer-or-farther comes from
// the depth map. Averaging the signed CoC instead cancelled near against far where the two meet,
// and the +-120 deg passes there barely blurred (PassesGLTest: NearAndFarBlurMeetingDoNotCancel).
//
// Where this differs from the paper, each on purpose:
//  - the first pass runs along the hexagon's edge nearest an axis: 0 deg for a flat top (the
//    paper's figures, --blade-rotation 30), 90 deg for the default corner on top (Pipeline.cpp);
//  - a pixel with |CoC| < 0.5 px is copied as it is (the centre texel fetched exactly), so
//    in-focus pixels stay bit-exact;
//  - small CoCs use every stride-th tap while neighbouring taps stay 1.5 px apart (tapStride());
//  - where the bleeding rule leaves less than one tap's worth of weight (sharp foreground all
//    around), the centre fills the missing weight; the paper divides by the total weight, which
//    may be 0.
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uSource; // rgb + CoC (px) in alpha: signed (the CoC pass) or |CoC|; linear filtering
layout(binding = 1) uniform sampler2D uDepth;  // metres, nearest filtering

layout(std140, binding = 0) uniform HexBlurParams {
    vec4 offsets[MAX_SAMPLES]; // xy: texture-space offset per pixel of CoC diameter
    int sampleCount;
    float bleedingBias;
    float bleedingMult;
    float cocToPaperUnits;     // 1 / image height in pixels
    float maxTapSpacing;       // pixels; small CoCs use every stride-th tap while taps stay this close
};

// The largest stride dividing sampleCount - 1 (so the taps used stay symmetric and still span
// the whole diameter) that keeps neighbouring taps at most maxTapSpacing pixels apart.
int tapStride(float diameter)
{
    const int intervals = sampleCount - 1;
    for (int stride = intervals; stride > 1; --stride)
        if (intervals % stride == 0 && diameter * float(stride) <= maxTapSpacing * float(intervals))
            return stride;
    return 1;
}

// |CoC| at `coords` as the linear sampler would interpolate it, but of each texel's |CoC|: a
// filtered fetch of the signed CoC (the first pass reads the CoC pass) would mix near and far
// blur towards 0 where they meet. In the +-120 deg passes alpha is |CoC| already.
float tapDiameter(vec2 coords)
{
    const vec2 texel = coords * vec2(textureSize(uSource, 0)) - 0.5;
    const vec2 f = fract(texel);
    // textureGather's order: (0, 1), (1, 1), (1, 0), (0, 0) of the 2x2 footprint.
    const vec4 a = abs(textureGather(uSource, coords, 3));
    return mix(mix(a.w, a.z, f.x), mix(a.x, a.y, f.x), f.y);
}

void main()
{
    // The centre texel exactly: a filtered fetch at the pixel centre is not exact on every
    // driver (llvmpipe mixes in a neighbour by one half-float step), which would move in-focus pixels.
    const vec4 texel = texelFetch(uSource, ivec2(gl_FragCoord.xy), 0);
    const float diameter = abs(texel.a);
    const vec4 center = vec4(texel.rgb, diameter);
    if (diameter < 0.5) { // a CoC below half a pixel is in focus: keep the pixel as it is
        outColor = center;
        return;
    }
    // The pixel centre from gl_FragCoord, not an interpolated uv: the tiles (tiles.vert) and the
    // full-screen triangle interpolate uv with different rounding, which moved taps by an ulp and
    // outputs by an 8-bit step between the plan and every pass on every pixel.
    const vec2 uv = gl_FragCoord.xy / vec2(textureSize(uSource, 0));
    const float centerDepth = textureLod(uDepth, uv, 0.0).r;
    const float centerBlur = diameter * cocToPaperUnits;

    vec4 sum = vec4(0.0);
    float totalWeight = 0.0;
    const int stride = tapStride(diameter);
    for (int i = 0; i < sampleCount; i += stride) {
        const vec2 coords = uv + offsets[i].xy * diameter;
        const vec4 tap = vec4(textureLod(uSource, coords, 0.0).rgb, tapDiameter(coords));
        const float tapDepth = textureLod(uDepth, coords, 0.0).r;
        const float tapBlur = tap.a * cocToPaperUnits;
        float weight = tapDepth < centerDepth ? tapBlur * bleedingMult : 1.0;
        weight = centerBlur > tapBlur + bleedingBias ? weight : 1.0;
        weight = clamp(weight, 0.0, 1.0);
        sum += tap * weight;
        totalWeight += weight;
    }
    // When the bleeding rule leaves less than one tap's worth of weight (sharp foreground all
    // around), the centre fills the rest: the result moves continuously from the normalised
    // average (totalWeight >= 1, the usual case, unchanged) to the centre itself (totalWeight 0),
    // instead of jumping from the foreground's average to the centre, and never divides by 0.
    outColor = (sum + center * max(1.0 - totalWeight, 0.0)) / max(totalWeight, 1.0);
}
