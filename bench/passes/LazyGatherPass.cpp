// SPDX-License-Identifier: LGPL-2.1-or-later
// Lazy gather pass: the eight points in texture space, the threshold, one draw.
#include "bench/passes/LazyGatherPass.hpp"

#include <algorithm>

#include "filter/passes/Pass.hpp"

namespace defocus {

LazyGatherPass::LazyGatherPass()
    : program_("fullscreen.vert", "lazy_gather.frag", kName),
      uniforms_(sizeof(Uniforms), "lazy gather params"),
      linear_(GL_LINEAR, "lazy gather linear")
{
}

void LazyGatherPass::run(const gl::Texture& source, float maxCocPx, float threshold, const gl::Framebuffer& target)
{
    Uniforms u{};
    for (std::size_t i = 0; i < 8; ++i) {
        u.taps[i][0] = kTaps[2 * i] / static_cast<float>(target.width());
        u.taps[i][1] = kTaps[2 * i + 1] / static_cast<float>(target.height());
    }
    u.maxCocPx = std::max(maxCocPx, 1e-6f);
    u.threshold = threshold;
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);
    target.bindForDraw();
    program_.use();
    bindTexture(0, source.id(), linear_.id());
    drawFullscreenTriangle();
}

} // namespace defocus
