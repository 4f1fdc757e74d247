// SPDX-License-Identifier: LGPL-2.1-or-later
// Shows an intermediate target: colour as is, depth or signed CoC colour-mapped. Shader: view.frag.
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class ViewPass {
public:
    static constexpr const char* kName = "view";
    enum class Mode { Color = 0, Depth = 1, Coc = 2 };

    ViewPass();
    /// Depth: `low`..`high` metres on a log scale. Coc: `high` is the CoC (px) at full colour.
    void run(const gl::Texture& source, Mode mode, float low, float high, const gl::Framebuffer& target);

private:
    /// Mirrors the std140 block ViewParams in view.frag.
    struct Uniforms {
        int mode;
        float rangeLow;
        float rangeHigh;
        int sourceShift; ///< log2 of target size / source size: 0, or 1 for a half-size source
    };
    gl::Program program_;
    gl::UniformBuffer uniforms_;
    gl::Sampler nearest_;
};

} // namespace defocus
