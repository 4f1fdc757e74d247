// SPDX-License-Identifier: LGPL-2.1-or-later
// Pass 5: the hexagon from the two results of the last blur pass: min() of the McIntosh diagonal
// blurs (optionally with the foreground layer over it), or the sum of the rhombus pass's pair.
// Shader: composite.frag.
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

class CompositePass : public ShadedPass {
public:
    static constexpr const char* kName = "composite";
    CompositePass();
    /// `nearA`/`nearB`: the foreground layer's two diagonal blurs, or null without a near field.
    void run(const gl::Texture& diagonalA, const gl::Texture& diagonalB, const gl::Framebuffer& target,
             const gl::Texture* nearA = nullptr, const gl::Texture* nearB = nullptr);
    /// (A + 2 B) / 3 of the second rhombus pass's targets (rhombus_blur.frag).
    void runSum(const gl::Texture& a, const gl::Texture& b, const gl::Framebuffer& target);

private:
    gl::Program program_;
    gl::Program nearProgram_; ///< NEAR_FIELD variant
    gl::Program sumProgram_;  ///< SUM variant
    gl::Sampler nearest_;
};

} // namespace defocus
