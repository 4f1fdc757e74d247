#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Synthetic scenes (sources/SyntheticScene.cpp): world-space vertices seen by one eye of the lens.
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUv;
layout(location = 3) in uint aMaterial;

// Mirrors CameraBlock in sources/SyntheticScene.cpp.
layout(std140, binding = 0) uniform Camera {
    mat4 viewProjection; // this render's eye: off-axis frustum through the fixed focus plane, jittered
    mat4 view;           // the lens centre's world -> camera transform
} uCamera;

layout(location = 0) out vec3 vNormal;
layout(location = 1) out vec2 vUv;
layout(location = 2) flat out uint vMaterial;
layout(location = 3) out float vDepth;

// The depth-only pass and the shading pass must compute the same depth bit for bit (the
// shading pass tests for EQUAL): invariance across the two programs guarantees it.
invariant gl_Position;

void main()
{
    gl_Position = uCamera.viewProjection * vec4(aPosition, 1.0);
    vNormal = aNormal;
    vUv = aUv;
    vMaterial = aMaterial;
    // Planar depth: distance from the lens plane along the view axis (camera looks down -z).
    // Affine in the position, so interpolating it over a triangle is exact.
    vDepth = -(uCamera.view * vec4(aPosition, 1.0)).z;
}
