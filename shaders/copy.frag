#version 450 core
// Copies the source texel: tiles in focus skip the blur and keep what the previous pass wrote.
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uSource;

void main()
{
    outColor = texelFetch(uSource, ivec2(gl_FragCoord.xy), 0);
}
