// Helpers shared by the fragment shaders (included, so no #version here).

// The exact sRGB transfer functions (IEC 61966-2-1).
vec3 srgbToLinear(vec3 c)
{
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}

// Replaces NaN and +-Inf with 0 and keeps values inside what the render target can hold.
vec3 sanitizeColor(vec3 c, float largest)
{
    bvec3 bad = bvec3(isnan(c.r) || isinf(c.r), isnan(c.g) || isinf(c.g), isnan(c.b) || isinf(c.b));
    return clamp(mix(c, vec3(0.0), bad), vec3(0.0), vec3(largest));
}
