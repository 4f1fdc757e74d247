// SPDX-License-Identifier: LGPL-2.1-or-later
// Calibration pass: draws calibration.frag over the whole target.
#include "bench/passes/CalibrationPass.hpp"

#include "filter/passes/Pass.hpp"

namespace defocus {

CalibrationPass::CalibrationPass()
    : program_("fullscreen.vert", "calibration.frag", kName), linear_(GL_LINEAR, "calibration linear")
{
}

void CalibrationPass::run(const gl::Texture& source, const gl::Framebuffer& target)
{
    target.bindForDraw();
    program_.use();
    bindTexture(0, source.id(), linear_.id());
    drawFullscreenTriangle();
}

} // namespace defocus
