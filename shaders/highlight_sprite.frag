#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Bokeh sprites, step 2: the aperture's coverage of this pixel times the sprite's light, added to
// the output (blending GL_ONE, GL_ONE), where the gather would have brought the same light: to
// a pixel with a blur of its own (|CoC| >= 1 px), unless it lies in front of the sprite and is
// sharper (the bleeding rule keeps background blur off sharper foreground); and with the near
// field, from a sprite in front of the pixel and blurrier than it, whatever the pixel's blur.
// Pixels in focus are otherwise kept, as the gather keeps them.
#include "coc_params.glsl"
#include "aperture_sprite.glsl"

layout(std430, binding = 0) readonly buffer Sprites {
    uint vertexCount; // DrawArraysIndirectCommand (highlight_sprites.comp)
    uint instanceCount;
    uint firstVertex;
    uint baseInstance;
    uint capacity;
    uint found;
    uint unused[2];
    vec4 sprites[];   // per sprite: (x, y, signed CoC of the gather, the aperture's area), (light rgb, 0)
};

layout(location = 0) in vec2 vOffset;
layout(location = 1) flat in vec4 vLight;
layout(location = 2) flat in float vRadius;
layout(location = 0) out vec4 outColor;

layout(binding = 1) uniform sampler2D uDepth; // metres, holes filled

void main()
{
    const float sprite = vLight.a;
    const float here = signedCoc(texelFetch(uDepth, ivec2(gl_FragCoord.xy), 0).r);
    const bool gathers = abs(here) >= 1.0 && !(here < sprite - 2.0 && abs(here) < abs(sprite));
    const bool foreground = nearField != 0 && sprite < here && abs(sprite) > abs(here);
    const float coverage = gathers || foreground ? apertureCoverage(vOffset, vRadius, sprite < 0.0) : 0.0;
    outColor = vec4(vLight.rgb * coverage, 0.0);
}
