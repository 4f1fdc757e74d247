#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// One triangle that covers the viewport; uv runs 0..1 over it. Shared by every pass.
//
//   (-1,3)
//     |\
//     |  \
//     |____\ (3,-1)      the part inside [-1,1]^2 is the screen
//  (-1,-1)
layout(location = 0) out vec2 vUv;

void main()
{
    const vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    vUv = corner;
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
