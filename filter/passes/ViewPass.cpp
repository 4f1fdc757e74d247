// SPDX-License-Identifier: LGPL-2.1-or-later
// View pass: draws view.frag with the chosen mode and range.
#include "filter/passes/ViewPass.hpp"

#include "filter/passes/Pass.hpp"

namespace defocus {

ViewPass::ViewPass()
    : program_("fullscreen.vert", "view.frag", kName),
      uniforms_(sizeof(Uniforms), "view params"),
      nearest_(GL_NEAREST, "view nearest")
{
}

void ViewPass::run(const gl::Texture& source, Mode mode, float low, float high, const gl::Framebuffer& target)
{
    // A half- or quarter-size target (Resolution::Half) is shown at the frame's size, each texel
    // as 2x2 or 4x4.
    int shift = 0;
    while (shift < 2 && (source.width() << shift) < target.width())
        ++shift;
    const Uniforms u{static_cast<int>(mode), low, high, shift};
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);
    target.bindForDraw();
    program_.use();
    bindTexture(0, source.id(), nearest_.id());
    drawFullscreenTriangle();
}

} // namespace defocus
