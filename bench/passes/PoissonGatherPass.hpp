// SPDX-License-Identifier: LGPL-2.1-or-later
// Riguer, Tatarchuk & Isidoro's 12-tap Poisson gather with their bleeding rule, one pass over the
// CoC pass's output. Shader: poisson_gather.frag.
#pragma once

#include <array>

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class PoissonGatherPass {
public:
    static constexpr const char* kName = "poisson-gather";
    /// The ShaderX2 chapter's filterTaps: 12 points in the unit disc (Riguer et al. 2004).
    static constexpr std::array<float, 24> kTaps{
        -0.326212f, -0.405805f, -0.840144f, -0.07358f,  -0.695914f, 0.457137f, -0.203345f, 0.620716f,
        0.96234f,   -0.194983f, 0.473434f,  -0.480026f, 0.519456f,  0.767022f, 0.185461f,  -0.893124f,
        0.507431f,  0.064425f,  0.89642f,   0.412458f,  -0.32194f,  -0.932615f, -0.791559f, -0.597705f};

    PoissonGatherPass();
    /// `source`: rgb + signed CoC in pixels (the CoC pass's target); `depth`: filled depth in
    /// metres; `maxCocPx` (> 0): the CoC that counts as blurriness 1, the lens's max-coc. The disc
    /// is scaled by the centre's CoC radius (half its diameter), so it covers the circle of
    /// confusion.
    void run(const gl::Texture& source, const gl::Texture& depth, float maxCocPx, const gl::Framebuffer& target);

private:
    /// Mirrors the std140 block PoissonGatherParams in poisson_gather.frag.
    struct Uniforms {
        float taps[12][4];
        float maxCocPx;
        float pad[3];
    };
    gl::Program program_;
    gl::UniformBuffer uniforms_;
    gl::Sampler linear_;
    gl::Sampler nearest_;
};

} // namespace defocus
