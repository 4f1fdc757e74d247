#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Instanced 16x16 tiles instead of one full-screen triangle: each instance is one tile of the
// target, drawn as a 4-vertex strip; uv matches fullscreen.vert's, so fragment shaders are shared.
layout(location = 0) in ivec2 aTile; // per instance: tile column, row
layout(location = 0) out vec2 vUv;

layout(std140, binding = 1) uniform TileParams {
    vec2 targetSize; // pixels
    float tileSize;  // pixels
    float tilePad;
};

void main()
{
    const vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));
    const vec2 pixel = min((vec2(aTile) + corner) * tileSize, targetSize);
    vUv = pixel / targetSize;
    gl_Position = vec4(vUv * 2.0 - 1.0, 0.0, 1.0);
}
