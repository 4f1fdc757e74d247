// SPDX-License-Identifier: LGPL-2.1-or-later
// Y'CbCr to colour pass: yuv_to_rgb.frag with the coefficients of ColorSpace's yuvCoefficients().
#include "filter/passes/YuvToRgbPass.hpp"

#include "filter/ColorSpace.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

namespace {
constexpr GLint kCoefficientsLocation = 0;
constexpr GLint kMoreLocation = 1;
} // namespace

YuvToRgbPass::YuvToRgbPass()
    : i420_("fullscreen.vert", "yuv_to_rgb.frag", "yuv-to-rgb I420"),
      nv12_("fullscreen.vert", "yuv_to_rgb.frag", "yuv-to-rgb NV12", {"NV12 1"}),
      nearest_(GL_NEAREST, "yuv-to-rgb nearest")
{
}

void YuvToRgbPass::run(const gl::Texture& luma, const gl::Texture& cb, const gl::Texture* cr, YuvImage::Matrix matrix,
                       YuvImage::Range range, const gl::Framebuffer& target)
{
    const gl::Program& program = cr ? i420_ : nv12_;
    const YuvCoefficients c = yuvCoefficients(matrix, range);
    glProgramUniform4i(program.id(), kCoefficientsLocation, c.yOffset, c.yScale, c.crToR, c.cbToG);
    glProgramUniform2i(program.id(), kMoreLocation, c.crToG, c.cbToB);
    bindTexture(0, luma.id(), nearest_.id());
    bindTexture(1, cb.id(), nearest_.id());
    if (cr)
        bindTexture(2, cr->id(), nearest_.id());
    target.bindForDraw();
    program.use();
    drawFullscreenTriangle();
}

} // namespace defocus
