// Pass 5: min() of the two diagonal blurs, the hexagon. Shader: composite.frag.
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class CompositePass {
public:
    static constexpr const char* kName = "composite";
    CompositePass();
    void run(const gl::Texture& diagonalA, const gl::Texture& diagonalB, const gl::Framebuffer& target);

private:
    gl::Program program_;
    gl::Sampler nearest_;
};

} // namespace defocus
