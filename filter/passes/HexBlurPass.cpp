// SPDX-License-Identifier: LGPL-2.1-or-later
// Directional blur pass: CPU-computed, aspect-corrected tap offsets + the bleeding-fix constants.
#include "filter/passes/HexBlurPass.hpp"

#include <cassert>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "filter/passes/Pass.hpp"

namespace defocus {

HexBlurPass::HexBlurPass()
    : program_("fullscreen.vert", "hex_blur.frag", "hex_blur", {fmt::format("MAX_SAMPLES {}", kMaxSamples)}),
      tileProgram_("tiles.vert", "hex_blur.frag", "hex_blur tiles", {fmt::format("MAX_SAMPLES {}", kMaxSamples)}),
      uniforms_(sizeof(Uniforms), "hex blur params"),
      linear_(GL_LINEAR, "hex blur linear"),
      nearest_(GL_NEAREST, "hex blur nearest")
{
}

std::vector<glm::vec2> HexBlurPass::offsets(float angleDegrees, int samples, int width, int height)
{
    assert(samples >= 2 && samples <= kMaxSamples);
    // Image rows run top to bottom in our textures, so a counter-clockwise screen angle moves
    // up, i.e. towards smaller v.
    const double angle = angleDegrees * std::numbers::pi / 180.0;
    const glm::vec2 half(static_cast<float>(0.5 * std::cos(angle) / width),
                         static_cast<float>(-0.5 * std::sin(angle) / height));
    std::vector<glm::vec2> result(static_cast<std::size_t>(samples));
    for (int i = 0; i < samples; ++i) {
        const float t = static_cast<float>(i) / static_cast<float>(samples - 1);
        result[static_cast<std::size_t>(i)] = -half + 2.0f * t * half;
    }
    return result;
}

void HexBlurPass::run(const gl::Texture& source, const gl::Texture& depth, float angleDegrees, int samples,
                      const gl::Framebuffer& target, const TileList* tiles)
{
    Uniforms u{};
    const auto taps = offsets(angleDegrees, samples, target.width(), target.height());
    for (std::size_t i = 0; i < taps.size(); ++i) {
        u.offsets[i][0] = taps[i].x;
        u.offsets[i][1] = taps[i].y;
    }
    u.sampleCount = samples;
    u.bleedingBias = kBleedingBias;
    u.bleedingMult = kBleedingMult;
    u.cocToPaperUnits = 1.0f / static_cast<float>(target.height());
    u.maxTapSpacing = kMaxTapSpacingPx;
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);
    bindTexture(0, source.id(), linear_.id());
    bindTexture(1, depth.id(), nearest_.id());
    shade(tiles ? tileProgram_ : program_, target, tiles);
}

} // namespace defocus
