// SPDX-License-Identifier: LGPL-2.1-or-later
// Helpers shared by the fragment shaders (included, so no #version here).

// The exact sRGB transfer functions (IEC 61966-2-1).
vec3 srgbToLinear(vec3 c)
{
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}

// Keeps colour finite and inside what the render target holds: NaN becomes 0, negatives 0, and
// +Inf or anything above `largest` becomes `largest` (a blown-out highlight stays bright).
// filter/ColorSpace.cpp's sanitizeLinear() does the same on the CPU: keep the two in step.
vec3 sanitizeColor(vec3 c, float largest)
{
    const bvec3 nan = bvec3(isnan(c.r), isnan(c.g), isnan(c.b));
    return clamp(mix(c, vec3(0.0), nan), vec3(0.0), vec3(largest));
}

// Rec. 709 luminance of linear RGB (filter/SceneAnalysis.cpp uses the same weights).
float luminance(vec3 c)
{
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}
