// SPDX-License-Identifier: LGPL-2.1-or-later
// The 8-point "lazy" gather with blurriness-difference rejection (GameStudio wiki), one pass over
// the CoC pass's output. Shader: lazy_gather.frag.
#pragma once

#include <array>

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class LazyGatherPass {
public:
    static constexpr const char* kName = "lazy-gather";
    /// The article's eight points: the unit circle's axis points and (+-0.4, +-0.4).
    static constexpr std::array<float, 16> kTaps{1.0f, 0.0f,  -1.0f, 0.0f,  0.0f,  1.0f, 0.0f, -1.0f,
                                                 0.4f, 0.4f,  -0.4f, 0.4f,  -0.4f, -0.4f, 0.4f, -0.4f};
    /// Largest blurriness difference (fraction of max-coc) a tap may have before it is replaced
    /// by the centre. The article leaves it open. On the Blender scene (max-coc 64, full
    /// resolution, RGBA32F) it hardly matters: 0.02 -> 23.79 dB, 0.05 -> 24.21, 0.1 -> 24.31,
    /// 0.2 -> 24.36, 0.4 -> 24.26, and no rejection at all (1) -> 24.45, because the truth does
    /// blur foreground over sharper background, which the rejection forbids. 0.2 is the best
    /// setting that still rejects.
    static constexpr float kDefaultThreshold = 0.2f;

    LazyGatherPass();
    /// `source`: rgb + signed CoC in pixels; `maxCocPx` (> 0): the CoC of blurriness 1;
    /// `threshold`: see kDefaultThreshold. The points are scaled by the centre's CoC radius.
    void run(const gl::Texture& source, float maxCocPx, float threshold, const gl::Framebuffer& target);

private:
    /// Mirrors the std140 block LazyGatherParams in lazy_gather.frag.
    struct Uniforms {
        float taps[8][4];
        float maxCocPx;
        float threshold;
        float pad[2];
    };
    gl::Program program_;
    gl::UniformBuffer uniforms_;
    gl::Sampler linear_;
};

} // namespace defocus
