#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Synthetic scenes (sources/SyntheticScene.cpp): procedural surfaces, lit by a sun and a sky,
// or emitting HDR light. With SYNTHETIC_DEPTH defined it writes the planar depth instead.
layout(location = 0) in vec3 vNormal;
layout(location = 1) in vec2 vUv;
layout(location = 2) flat in uint vMaterial;
layout(location = 3) in float vDepth;

layout(location = 0) out vec4 outColor;

#ifdef SYNTHETIC_DEPTH

void main()
{
    outColor = vec4(vDepth, 0.0, 0.0, 1.0);
}

#else

// Mirrors MaterialBlock in sources/SyntheticScene.cpp.
struct Material {
    vec4 colorAPattern; // rgb: albedo (or light colour); a: pattern (SceneDescription's Pattern)
    vec4 colorBScale;   // rgb: second albedo; a: period, metres
    vec4 emission;      // x: > 0 emits colorA * x, unlit
};
layout(std430, binding = 0) readonly buffer Materials {
    Material materials[];
};

const float kFlat = 0.0, kChecker = 1.0, kStripes = 2.0, kNoise = 3.0, kBricks = 4.0;

// Light: a sun from the upper left behind the camera and a sky dome, both white. Lambertian
// surfaces only, so a surface looks the same from every point of the lens.
const vec3 kSunDirection = normalize(vec3(-0.45, 0.8, 0.55));
const float kSun = 2.2;
const float kSky = 0.45;

// A square wave of period 2 in x, box-filtered over a footprint w: its mean over [x - w/2,
// x + w/2] in [-1, 1] (the integral of the wave is a triangle wave; I. Quilez, "filtered
// checkerboard"). Filtering keeps far patterns from aliasing into moire.
vec2 filteredSquare(vec2 x, vec2 w)
{
    w = max(w, vec2(1e-4));
    return 2.0 * (abs(fract((x - 0.5 * w) * 0.5) - 0.5) - abs(fract((x + 0.5 * w) * 0.5) - 0.5)) / w;
}

float hash(vec2 p)
{
    p = fract(p * vec2(123.34, 456.21));
    p += dot(p, p + 45.32);
    return fract(p.x * p.y);
}

float valueNoise(vec2 p)
{
    const vec2 i = floor(p);
    const vec2 f = fract(p);
    const vec2 u = f * f * (3.0 - 2.0 * f);
    return mix(mix(hash(i), hash(i + vec2(1.0, 0.0)), u.x), mix(hash(i + vec2(0.0, 1.0)), hash(i + vec2(1.0, 1.0)), u.x),
               u.y);
}

// Four octaves, the finer ones faded out where they would be smaller than a pixel.
float fbm(vec2 p, float footprint)
{
    float value = 0.0, amplitude = 0.5, scale = 1.0;
    for (int octave = 0; octave < 4; ++octave) {
        const float fade = clamp(1.5 - footprint * scale, 0.0, 1.0);
        value += amplitude * mix(0.5, valueNoise(p * scale), fade);
        amplitude *= 0.5;
        scale *= 2.07;
    }
    return value / 0.9375;
}

// Mortar lines 6% of the brick height wide; odd rows shifted by half a brick.
float bricks(vec2 p)
{
    const float row = floor(p.y);
    const vec2 q = vec2(p.x * 0.5 + 0.5 * mod(row, 2.0), p.y);
    const vec2 edge = min(fract(q), 1.0 - fract(q)) * vec2(2.0, 1.0);
    return step(0.03, min(edge.x, edge.y));
}

// `uvFootprint` is fwidth(vUv): derivatives are taken of the varying only, never of values read
// from the material buffer, which llvmpipe does not load for the helper pixels derivatives use.
vec3 albedo(Material m, vec2 uvFootprint)
{
    const vec3 a = m.colorAPattern.rgb, b = m.colorBScale.rgb;
    const float pattern = m.colorAPattern.a;
    const vec2 p = vUv / m.colorBScale.a;
    const vec2 w = uvFootprint / m.colorBScale.a;
    if (pattern == kChecker) {
        const vec2 s = filteredSquare(p, w);
        return mix(a, b, 0.5 - 0.5 * s.x * s.y);
    }
    if (pattern == kStripes)
        return mix(a, b, 0.5 - 0.5 * filteredSquare(p, w).x);
    if (pattern == kNoise)
        return mix(a, b, smoothstep(0.25, 0.75, fbm(p, max(w.x, w.y))));
    if (pattern == kBricks) {
        // Per-brick tint so the wall has texture at two scales.
        const float row = floor(p.y);
        const float brick = floor(p.x * 0.5 + 0.5 * mod(row, 2.0));
        const vec3 tint = a * (0.75 + 0.5 * hash(vec2(brick, row)));
        return mix(b, tint, bricks(p));
    }
    return a;
}

void main()
{
    const vec2 uvFootprint = fwidth(vUv);
    const Material m = materials[vMaterial];
    if (m.emission.x > 0.0) {
        outColor = vec4(m.colorAPattern.rgb * m.emission.x, 1.0);
        return;
    }
    const vec3 n = normalize(vNormal);
    const float light = kSun * max(dot(n, kSunDirection), 0.0) + kSky * (0.75 + 0.25 * n.y);
    outColor = vec4(albedo(m, uvFootprint) * light, 1.0);
}

#endif
