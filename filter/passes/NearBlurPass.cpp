// SPDX-License-Identifier: LGPL-2.1-or-later
// Near field blur pass: same tap offsets as the McIntosh blur, no bleeding rule (the layer holds
// only foreground, premultiplied), radius from the dilated tile maxima.
#include "filter/passes/NearBlurPass.hpp"

#include <fmt/format.h>

#include "filter/passes/Pass.hpp"

namespace defocus {

NearBlurPass::NearBlurPass()
    : program_("tiles.vert", "near_blur.frag", "near_blur", {fmt::format("MAX_SAMPLES {}", HexBlurPass::kMaxSamples)}),
      uniforms_(sizeof(Uniforms), "near blur params"),
      linear_(GL_LINEAR, "near blur linear")
{
}

void NearBlurPass::run(const gl::Texture& source, const gl::Texture& nearRadius, float angleDegrees, int samples,
                       bool firstPass, const gl::Framebuffer& target, const TileList& tiles)
{
    Uniforms u{};
    const auto taps = HexBlurPass::offsets(angleDegrees, samples, target.width(), target.height());
    for (std::size_t i = 0; i < taps.size(); ++i) {
        u.offsets[i][0] = taps[i].x;
        u.offsets[i][1] = taps[i].y;
    }
    u.sampleCount = samples;
    u.firstPass = firstPass ? 1 : 0;
    u.maxTapSpacing = HexBlurPass::kMaxTapSpacingPx;
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);
    target.bindForDraw();
    const float transparent[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    glClearBufferfv(GL_COLOR, 0, transparent);
    bindTexture(0, source.id(), linear_.id());
    bindTexture(2, nearRadius.id(), linear_.id());
    shade(program_, target, &tiles);
}

} // namespace defocus
