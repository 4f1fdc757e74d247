#version 450 core
// SPDX-License-Identifier: LGPL-2.1-or-later
// 8-bit Y'CbCr to the frame's colour bytes (R'G'B', sRGB-encoded as the decoder meant it), in
// the integer arithmetic of convertYuv() (filter/ColorSpace.cpp), so that the GPU and the CPU
// give the same bytes: each pixel's Y' with the Cb and Cr of its 2x2 block (4:2:0) or of its
// pair (4:2:2). I420: three R8UI planes; NV12 (defined): luma R8UI and Cb, Cr interleaved in one
// RG8UI plane; YUYV (defined): one RG8UI plane of the image's size, Y' in red, the pair's Cb
// (even columns) or Cr (odd) in green.
layout(location = 0) out vec4 outColor;

layout(binding = 0) uniform usampler2D uLuma; // YUYV: the packed pairs
#if !defined(YUYV)
layout(binding = 1) uniform usampler2D uCb; // NV12: Cb in red, Cr in green
#endif
#if !defined(NV12) && !defined(YUYV)
layout(binding = 2) uniform usampler2D uCr;
#endif
// YuvCoefficients: yOffset, yScale, crToR, cbToG; then crToG, cbToB.
layout(location = 0) uniform ivec4 uCoefficients;
layout(location = 1) uniform ivec2 uMore;

void main()
{
    const ivec2 pixel = ivec2(gl_FragCoord.xy);
    const int y = int(texelFetch(uLuma, pixel, 0).r);
#ifdef YUYV
    const int pair = pixel.x & ~1;
    const int u = int(texelFetch(uLuma, ivec2(pair, pixel.y), 0).g) - 128;
    const int v = int(texelFetch(uLuma, ivec2(pair + 1, pixel.y), 0).g) - 128;
#elif defined(NV12)
    const uvec2 chroma = texelFetch(uCb, pixel / 2, 0).rg;
    const int u = int(chroma.r) - 128, v = int(chroma.g) - 128;
#else
    const int u = int(texelFetch(uCb, pixel / 2, 0).r) - 128, v = int(texelFetch(uCr, pixel / 2, 0).r) - 128;
#endif
    const int l = uCoefficients.y * (y - uCoefficients.x) + 128;
    const ivec3 rgb = clamp(ivec3(l + uCoefficients.z * v, l - uCoefficients.w * u - uMore.x * v, l + uMore.y * u) >> 8,
                            0, 255);
    outColor = vec4(vec3(rgb) / 255.0, 1.0);
}
