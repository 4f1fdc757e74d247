// SPDX-License-Identifier: LGPL-2.1-or-later
// Y'CbCr 4:2:0 planes, uploaded as they came, to the frame's colour bytes: the bytes BGR input
// would have uploaded (convertYuv() on the CPU gives the same). Shader: yuv_to_rgb.frag. Drawn:
// the colour texture (RGB8) is no image format a compute shader can store to.
#pragma once

#include "defocus/Frame.hpp"
#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class YuvToRgbPass {
public:
    YuvToRgbPass();
    /// Writes `target` (the colour bytes, the luma's size) from `luma` (R8UI) and `cb`, `cr`
    /// (I420: R8UI each, half size) or `cb` alone (NV12: RG8UI, Cb and Cr), with the
    /// coefficients of `matrix` and `range`. A vertex array must be bound.
    void run(const gl::Texture& luma, const gl::Texture& cb, const gl::Texture* cr, YuvImage::Matrix matrix,
             YuvImage::Range range, const gl::Framebuffer& target);

private:
    gl::Program i420_;
    gl::Program nv12_;
    gl::Sampler nearest_; ///< integer textures are incomplete under a linear filter
};

} // namespace defocus
