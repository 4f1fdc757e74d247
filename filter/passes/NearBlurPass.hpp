// SPDX-License-Identifier: LGPL-2.1-or-later
// The foreground (near field) layer's directional blurs. Shader: near_blur.frag.
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/HexBlurPass.hpp"
#include "filter/passes/TileList.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

class NearBlurPass : public ShadedPass {
public:
    NearBlurPass();
    /// Blurs `source` along `angleDegrees` over the diameter in `nearRadius` (a per-tile R32F
    /// texture, linearly filtered). `firstPass`: `source` is the CoC target and the premultiplied
    /// foreground layer is made from it on the fly. Draws `tiles` after clearing the target.
    void run(const gl::Texture& source, const gl::Texture& nearRadius, float angleDegrees, int samples,
             bool firstPass, const gl::Framebuffer& target, const TileList& tiles);

private:
    /// Mirrors the std140 block NearBlurParams in near_blur.frag.
    struct Uniforms {
        float offsets[HexBlurPass::kMaxSamples][4];
        int sampleCount;
        int firstPass;
        float maxTapSpacing;
        float pad;
    };
    gl::Program program_;
    gl::UniformBuffer uniforms_;
    gl::Sampler linear_;
};

} // namespace defocus
