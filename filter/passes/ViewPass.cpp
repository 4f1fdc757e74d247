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
    // A half-size target (Resolution::Half) is shown at the frame's size, each texel as 2x2.
    const int shift = source.width() < target.width() ? 1 : 0;
    const Uniforms u{static_cast<int>(mode), low, high, shift};
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);
    target.bindForDraw();
    program_.use();
    bindTexture(0, source.id(), nearest_.id());
    drawFullscreenTriangle();
}

} // namespace defocus
