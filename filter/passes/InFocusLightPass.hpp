// SPDX-License-Identifier: LGPL-2.1-or-later
// Lights in focus put back: the CoC pass lets a light in focus into the blur as what lies round
// it (coc.frag, bokeh sprites' frames), and this pass adds the rest of it to the output, by the
// share of the pixel that the blur left its own (under a blurred foreground, less). Shader:
// in_focus_light.frag.
#pragma once

#include <map>

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/CocParams.hpp"
#include "filter/passes/RhombusBlurPass.hpp"
#include "filter/passes/TileList.hpp"

namespace defocus {

class InFocusLightPass {
public:
    static constexpr const char* kName = "lights-in-focus";
    InFocusLightPass();
    /// What the pass reads: the frame and its filled depth as the CoC pass read them, the CoC
    /// target the rhombus blur ran on (the frame's size or half of it), and the blur's
    /// foreground diameter per tile in the blur's pixels (nullptr: no near field).
    struct Io {
        const gl::Texture& color;
        const gl::Texture& depth;
        const gl::Texture& coc;
        const gl::Texture* nearDiameter;
    };
    /// Adds to `target`, the frame-sized output, the light the CoC pass held back from the
    /// pixels in focus on `tiles` (SceneAnalysis::highlightTiles, frame-sized). `params`: the
    /// frame's, the CoC pass's (with its highlight threshold); `directions`, `taps`,
    /// `nearTileSize` and `blurShift` (0 full size, 1 half) the rhombus blur's. A vertex array
    /// must be bound.
    void run(const Io& io, const CocParams& params, const RhombusBlurPass::Directions& directions,
             int taps, int nearTileSize, int blurShift, const TileList& tiles, const gl::Framebuffer& target);

private:
    /// Mirrors the std140 block InFocusLightParams in in_focus_light.frag.
    struct Uniforms {
        float lines[4][4];
        float baseSteps[4];
        int maxTaps;
        int nearTileSize;
        int nearField;
        int blurShift;
    };
    /// One program per set of line modes (compile-time in the shader, as in the blur).
    const gl::Program& program(const RhombusBlurPass::Lines& lines);
    std::map<int, gl::Program> programs_;
    gl::UniformBuffer uniforms_;
    gl::Sampler nearest_;
    gl::Sampler linear_;
};

} // namespace defocus
