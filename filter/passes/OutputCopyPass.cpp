// SPDX-License-Identifier: LGPL-2.1-or-later
// Output copy pass: output_copy.frag through an RGBA8 texture view of the sRGB target.
#include "filter/passes/OutputCopyPass.hpp"

#include "filter/passes/Pass.hpp"

namespace defocus {

OutputCopyPass::OutputCopyPass()
    : program_("fullscreen.vert", "output_copy.frag", kName),
      swappedProgram_("fullscreen.vert", "output_copy.frag", "output-copy BGRA", {"SWAP_RED_BLUE 1"}),
      nearest_(GL_NEAREST, "output-copy nearest")
{
}

void OutputCopyPass::run(const gl::Texture& source, unsigned generation, const gl::Framebuffer& target,
                         bool swapRedBlue)
{
    // A view shares the source's storage; a new source (another size) needs a new view.
    if (!view_ || viewOf_ != generation) {
        GLuint id = 0;
        glGenTextures(1, &id);
        glTextureView(id, GL_TEXTURE_2D, source.id(), GL_RGBA8, 0, 1, 0, 1);
        view_ = gl::Handle<gl::deleteTexture>(id);
        viewOf_ = generation;
        gl::label(GL_TEXTURE, id, "output, undecoded view");
    }
    target.bindForDraw();
    (swapRedBlue ? swappedProgram_ : program_).use();
    bindTexture(0, view_.id(), nearest_.id());
    drawFullscreenTriangle();
}

} // namespace defocus
