// SPDX-License-Identifier: LGPL-2.1-or-later
// Poisson gather pass: the 12 taps in texture space, the blurriness unit, one draw.
#include "bench/passes/PoissonGatherPass.hpp"

#include <algorithm>

#include "filter/passes/Pass.hpp"

namespace defocus {

PoissonGatherPass::PoissonGatherPass()
    : program_("fullscreen.vert", "poisson_gather.frag", kName),
      uniforms_(sizeof(Uniforms), "poisson gather params"),
      linear_(GL_LINEAR, "poisson gather linear"),
      nearest_(GL_NEAREST, "poisson gather nearest")
{
}

void PoissonGatherPass::run(const gl::Texture& source, const gl::Texture& depth, float maxCocPx,
                            const gl::Framebuffer& target)
{
    Uniforms u{};
    for (std::size_t i = 0; i < 12; ++i) {
        u.taps[i][0] = kTaps[2 * i] / static_cast<float>(target.width());
        u.taps[i][1] = kTaps[2 * i + 1] / static_cast<float>(target.height());
    }
    u.maxCocPx = std::max(maxCocPx, 1e-6f);
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);
    target.bindForDraw();
    program_.use();
    bindTexture(0, source.id(), linear_.id());
    bindTexture(1, depth.id(), nearest_.id());
    drawFullscreenTriangle();
}

} // namespace defocus
