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
      yuyv_("fullscreen.vert", "yuv_to_rgb.frag", "yuv-to-rgb YUYV", {"YUYV 1"}),
      nearest_(GL_NEAREST, "yuv-to-rgb nearest")
{
}

void YuvToRgbPass::run(YuvImage::Layout layout, const gl::Texture (&planes)[3], YuvImage::Matrix matrix,
                       YuvImage::Range range, const gl::Framebuffer& target)
{
    const gl::Program& program = layout == YuvImage::Layout::I420   ? i420_
                                 : layout == YuvImage::Layout::Nv12 ? nv12_
                                                                    : yuyv_;
    const YuvCoefficients c = yuvCoefficients(matrix, range);
    glProgramUniform4i(program.id(), kCoefficientsLocation, c.yOffset, c.yScale, c.crToR, c.cbToG);
    glProgramUniform2i(program.id(), kMoreLocation, c.crToG, c.cbToB);
    for (int i = 0; i < yuvPlaneCount(layout); ++i)
        bindTexture(static_cast<GLuint>(i), planes[i].id(), nearest_.id());
    target.bindForDraw();
    program.use();
    drawFullscreenTriangle();
}

} // namespace defocus
