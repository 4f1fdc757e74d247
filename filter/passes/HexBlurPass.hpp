// SPDX-License-Identifier: LGPL-2.1-or-later
// One directional blur of the McIntosh hexagonal bokeh (pass 2, 3 or 4). Shader: hex_blur.frag.
#pragma once

#include <vector>

#include <glm/vec2.hpp>

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/TileList.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

class HexBlurPass : public ShadedPass {
public:
    static constexpr int kMaxSamples = 64;
    /// The paper's bleeding fix constants, in its unit (CoC as a fraction of image height).
    static constexpr float kBleedingBias = 0.02f;
    static constexpr float kBleedingMult = 30.0f;
    /// Taps of a small CoC are thinned while neighbours stay this close (pixels): more taps
    /// than that only resample the same bilinear footprints.
    static constexpr float kMaxTapSpacingPx = 1.5f;

    HexBlurPass();
    /// Blurs `source` (rgb + signed CoC) along `angleDegrees` (counter-clockwise on screen, 0 =
    /// horizontal) with `samples` taps; `depth` is the filled depth in metres. With `tiles`,
    /// only those tiles are drawn; otherwise the whole target.
    void run(const gl::Texture& source, const gl::Texture& depth, float angleDegrees, int samples,
             const gl::Framebuffer& target, const TileList* tiles = nullptr);

    /// Texture-space tap offsets per pixel of CoC diameter: `samples` points evenly spaced from
    /// -d/2 to +d/2 along the angle, divided by the image size so that pixels stay square.
    static std::vector<glm::vec2> offsets(float angleDegrees, int samples, int width, int height);

private:
    /// Mirrors the std140 block HexBlurParams in hex_blur.frag.
    struct Uniforms {
        float offsets[kMaxSamples][4];
        int sampleCount;
        float bleedingBias;
        float bleedingMult;
        float cocToPaperUnits;
        float maxTapSpacing;
    };
    gl::Program program_;
    gl::Program tileProgram_; ///< the same shader on tiles.vert
    gl::UniformBuffer uniforms_;
    gl::Sampler linear_;
    gl::Sampler nearest_;
};

} // namespace defocus
