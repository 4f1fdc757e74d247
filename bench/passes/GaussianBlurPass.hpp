// SPDX-License-Identifier: LGPL-2.1-or-later
// The 5x5 Gaussian whose spread follows the distance from the plane in focus (the WebGL "Toy
// Story" demo), one pass over the CoC pass's output. Shader: gaussian_blur.frag.
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class GaussianBlurPass {
public:
    static constexpr const char* kName = "gaussian-blur";

    GaussianBlurPass();
    /// `source`: rgb + signed CoC in pixels. The 5x5 grid's step is |CoC| / 4 of the centre.
    void run(const gl::Texture& source, const gl::Framebuffer& target);

private:
    /// Mirrors the std140 block GaussianBlurParams in gaussian_blur.frag.
    struct Uniforms {
        float taps[25][4];
    };
    gl::Program program_;
    gl::UniformBuffer uniforms_;
    gl::Sampler linear_;
};

} // namespace defocus
