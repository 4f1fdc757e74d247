// SPDX-License-Identifier: LGPL-2.1-or-later
// Composite pass: draws composite.frag over the two diagonal results (and the near field).
#include "filter/passes/CompositePass.hpp"

#include "filter/passes/Pass.hpp"

namespace defocus {

CompositePass::CompositePass()
    : program_("fullscreen.vert", "composite.frag", kName),
      nearProgram_("fullscreen.vert", "composite.frag", "composite near", {"NEAR_FIELD 1"}),
      sumProgram_("fullscreen.vert", "composite.frag", "composite sum", {"SUM 1"}),
      nearest_(GL_NEAREST, "composite nearest")
{
}

void CompositePass::run(const gl::Texture& diagonalA, const gl::Texture& diagonalB, const gl::Framebuffer& target,
                        const gl::Texture* nearA, const gl::Texture* nearB)
{
    bindTexture(0, diagonalA.id(), nearest_.id());
    bindTexture(1, diagonalB.id(), nearest_.id());
    const bool near = nearA && nearB;
    if (near) {
        bindTexture(2, nearA->id(), nearest_.id());
        bindTexture(3, nearB->id(), nearest_.id());
    }
    shade(near ? nearProgram_ : program_, target);
}

void CompositePass::runSum(const gl::Texture& a, const gl::Texture& b, const gl::Framebuffer& target)
{
    bindTexture(0, a.id(), nearest_.id());
    bindTexture(1, b.id(), nearest_.id());
    shade(sumProgram_, target);
}

} // namespace defocus
