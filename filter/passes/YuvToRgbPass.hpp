// SPDX-License-Identifier: LGPL-2.1-or-later
// Y'CbCr 4:2:0 planes or YUYV's packed pairs, uploaded as they came, to the frame's colour bytes:
// the bytes BGR input would have uploaded (convertYuv() on the CPU gives the same). Shader:
// yuv_to_rgb.frag. Drawn: the colour texture (RGB8) is no image format a compute shader can
// store to.
#pragma once

#include "defocus/Frame.hpp"
#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class YuvToRgbPass {
public:
    YuvToRgbPass();
    /// Writes `target` (the colour bytes, the image's size) from the `layout`'s planes: I420
    /// Y' (R8UI), Cb and Cr (R8UI each, half size); NV12 Y' (R8UI) and Cb, Cr (RG8UI, half size);
    /// YUYV the packed pairs alone (RG8UI, the image's size: Y', then Cb or Cr). With the
    /// coefficients of `matrix` and `range`. A vertex array must be bound.
    void run(YuvImage::Layout layout, const gl::Texture (&planes)[3], YuvImage::Matrix matrix, YuvImage::Range range,
             const gl::Framebuffer& target);

private:
    gl::Program i420_;
    gl::Program nv12_;
    gl::Program yuyv_;
    gl::Sampler nearest_; ///< integer textures are incomplete under a linear filter
};

} // namespace defocus
