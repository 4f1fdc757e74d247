// SPDX-License-Identifier: LGPL-2.1-or-later
// Gaussian pass: the 25 offsets and normalised weights, one draw.
#include "bench/passes/GaussianBlurPass.hpp"

#include <cmath>

#include "filter/passes/Pass.hpp"

namespace defocus {

GaussianBlurPass::GaussianBlurPass()
    : program_("fullscreen.vert", "gaussian_blur.frag", kName),
      uniforms_(sizeof(Uniforms), "gaussian blur params"),
      linear_(GL_LINEAR, "gaussian blur linear")
{
}

void GaussianBlurPass::run(const gl::Texture& source, const gl::Framebuffer& target)
{
    // The demo's weights come from a Gaussian of the texture-space offset with variance 4, which
    // at its tiny offsets is flat (a box filter) and sums to 25 / (8 pi), not 1. Here the grid
    // step is |CoC| / 4 and sigma is one step: a uniform disc of diameter d has a standard
    // deviation of d / 4 per axis, so the Gaussian's spread matches the circle of confusion's;
    // the weights are normalised so flat colour stays flat.
    Uniforms u{};
    float total = 0.0f;
    for (int j = -2; j <= 2; ++j) {
        for (int i = -2; i <= 2; ++i) {
            const auto k = static_cast<std::size_t>((j + 2) * 5 + (i + 2));
            u.taps[k][0] = 0.25f * static_cast<float>(i) / static_cast<float>(target.width());
            u.taps[k][1] = 0.25f * static_cast<float>(j) / static_cast<float>(target.height());
            u.taps[k][2] = std::exp(-0.5f * static_cast<float>(i * i + j * j));
            total += u.taps[k][2];
        }
    }
    for (auto& tap : u.taps)
        tap[2] /= total;
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);
    target.bindForDraw();
    program_.use();
    bindTexture(0, source.id(), linear_.id());
    drawFullscreenTriangle();
}

} // namespace defocus
