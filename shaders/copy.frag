#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// Copies the source texel: tiles in focus skip the blur and keep what the previous pass wrote.
// TWO_TARGETS: the rhombus passes write two targets; in focus both hold the same texel.
layout(location = 0) out vec4 outColor;
#ifdef TWO_TARGETS
layout(location = 1) out vec4 outSecond;
#endif

layout(binding = 0) uniform sampler2D uSource;

void main()
{
    outColor = texelFetch(uSource, ivec2(gl_FragCoord.xy), 0);
#ifdef TWO_TARGETS
    outSecond = outColor;
#endif
}
