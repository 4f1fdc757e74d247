// Composite pass: draws composite.frag over the two diagonal results.
#include "filter/passes/CompositePass.hpp"

#include "filter/passes/Pass.hpp"

namespace defocus {

CompositePass::CompositePass()
    : program_("fullscreen.vert", "composite.frag", kName), nearest_(GL_NEAREST, "composite nearest")
{
}

void CompositePass::run(const gl::Texture& diagonalA, const gl::Texture& diagonalB, const gl::Framebuffer& target)
{
    target.bindForDraw();
    program_.use();
    bindTexture(0, diagonalA.id(), nearest_.id());
    bindTexture(1, diagonalB.id(), nearest_.id());
    drawFullscreenTriangle();
}

} // namespace defocus
