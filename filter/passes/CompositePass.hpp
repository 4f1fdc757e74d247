// Pass 5: min() of the two diagonal blurs, the hexagon; optionally the foreground layer over it.
// Shader: composite.frag.
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class CompositePass {
public:
    static constexpr const char* kName = "composite";
    CompositePass();
    /// `nearA`/`nearB`: the foreground layer's two diagonal blurs, or null without a near field.
    void run(const gl::Texture& diagonalA, const gl::Texture& diagonalB, const gl::Framebuffer& target,
             const gl::Texture* nearA = nullptr, const gl::Texture* nearB = nullptr);

private:
    gl::Program program_;
    gl::Program nearProgram_; ///< NEAR_FIELD variant
    gl::Sampler nearest_;
};

} // namespace defocus
