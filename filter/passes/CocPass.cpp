// CoC pass: uploads the lens coefficients and draws coc.frag.
#include "filter/passes/CocPass.hpp"

#include "filter/passes/Pass.hpp"

namespace defocus {

CocPass::CocPass()
    : program_("fullscreen.vert", "coc.frag", kName),
      uniforms_(sizeof(Uniforms), "coc params"),
      nearest_(GL_NEAREST, "coc nearest")
{
}

void CocPass::run(const gl::Texture& color, const gl::Texture& depth, const CocCoefficients& k, bool halfTarget,
                  const gl::Framebuffer& target)
{
    const Uniforms u{{k.nearScale, k.nearOffset, k.farScale, k.farOffset},
                     k.focusM,
                     k.maxCocPx,
                     k.inverseDepth ? 1 : 0,
                     halfTarget ? 65504.0f : 3.0e38f};
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);
    target.bindForDraw();
    program_.use();
    bindTexture(0, color.id(), nearest_.id());
    bindTexture(1, depth.id(), nearest_.id());
    drawFullscreenTriangle();
}

} // namespace defocus
