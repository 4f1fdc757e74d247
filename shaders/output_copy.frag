#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Copies the output's encoded bytes (read through an RGBA8 view of the sRGB target: no decoding)
// into a caller's RGBA8 texture, opaque. SWAP_RED_BLUE: the caller's texture holds BGRA.
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uSource;

void main()
{
    const vec4 texel = texelFetch(uSource, ivec2(gl_FragCoord.xy), 0);
#ifdef SWAP_RED_BLUE
    outColor = vec4(texel.bgr, 1.0);
#else
    outColor = vec4(texel.rgb, 1.0);
#endif
}
