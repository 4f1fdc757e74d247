// SPDX-License-Identifier: LGPL-2.1-or-later
// Depth prep on the GPU: the depth as it came (R32F metres, any size of the frame's aspect) made
// the frame's size by nearest neighbour and its holes filled by push-pull, and for float frames
// with bokeh sprites a light's edge put at the light's depth. The same result as prepareDepth()
// and putLightEdgesAtTheirLightsDepth() on the CPU (filter/DepthPrep.hpp), without the frame's
// depth touching the CPU. Shader: depth_prep.frag, one full-screen triangle per step and level.
#pragma once

#include <vector>

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

class DepthPrepPass : public ShadedPass {
public:
    static constexpr const char* kName = "depth-prep";
    DepthPrepPass();

    /// Fills `filledDepth` (R32F, the frame's size; `filled` its framebuffer) from `depth` (R32F
    /// metres, or with `unitsPerMetre` > 0 R16UI in those units; nullptr: the frame has no depth,
    /// and all of it sits at `fallbackM`, as when no pixel of `depth` is a measurement). `lightColor`: a float frame's linear colour, whose
    /// pixels above white take the depth of the brightest pixel round them if brighter; nullptr: no
    /// such step. Needs a vertex array bound (the full-screen triangle).
    void run(const gl::Texture* depth, double unitsPerMetre, float fallbackM, const gl::Texture* lightColor,
             const gl::Texture& filledDepth, const gl::Framebuffer& filled);
    /// The frame's size, RG32F: g is 1 where the last run's depth had a measurement, 0 at its
    /// holes (SceneMeasurePass counts them). Empty until a run with depth.
    const gl::Texture& measured() const { return levels_.empty() ? none_ : levels_.front().pyramid; }

private:
    struct Level {
        gl::Texture pyramid;    ///< RG32F: depth, weight
        gl::Framebuffer pyramidTarget;
        gl::Texture filled;     ///< R32F: its holes filled (PULL); none at level 0 and the coarsest
        gl::Framebuffer filledTarget;
    };
    /// depth_prep.frag's uniforms, at explicit locations.
    static constexpr GLint kSizeLocation = 0;     ///< uSize: the target's
    static constexpr GLint kFallbackLocation = 1; ///< uFallbackM (FILL)
    static constexpr GLint kMetresPerUnitLocation = 2; ///< uMetresPerUnit (SPLIT of 16-bit depth)
    /// Draws `program` over the whole of `target`.
    /// `program` over `target` (its size set), drawn or dispatched (setStage()).
    void draw(const gl::Program& program, const gl::Framebuffer& target) const;
    /// The program of `program` that runs: itself or its compute form.
    const gl::Program& staged(const gl::Program& program) const
    {
        return stage() == ShaderStage::Compute ? program.computeForm() : program;
    }

    gl::Program split_, splitUnits_, push_, pull_, fill_, lightEdges_;
    gl::Sampler nearest_;
    /// Level 0 has the frame's size, each next one half the last (rounded up), down to 1x1.
    std::vector<Level> levels_;
    gl::Texture unlit_; ///< the filled depth before the light edges
    gl::Framebuffer unlitTarget_;
    gl::Texture none_;
};

} // namespace defocus
