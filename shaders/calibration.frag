#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// A fixed workload shaped like one blur pass (16 filtered taps along a line, a weighted sum):
// timing regressions are reported as each pass's time over this one's, measured in the same
// run, so a slower or busier machine does not read as a slower pipeline.
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform sampler2D uSource;

void main()
{
    const vec2 step = vec2(1.0, 0.0) / vec2(textureSize(uSource, 0));
    vec4 sum = vec4(0.0);
    for (int i = 0; i < 16; ++i)
        sum += textureLod(uSource, vUv + step * (float(i) - 7.5), 0.0) * (1.0 + 0.01 * float(i));
    outColor = sum / 17.2;
}
