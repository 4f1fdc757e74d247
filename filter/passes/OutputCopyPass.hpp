// SPDX-License-Identifier: LGPL-2.1-or-later
// Copies the sRGB output target, byte for byte, into a caller's RGBA8 texture in RGBA or BGRA
// order with alpha 1: what glReadPixels would read, kept on the GPU. Shader: output_copy.frag.
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class OutputCopyPass {
public:
    static constexpr const char* kName = "output-copy";
    OutputCopyPass();
    /// `source`: a GL_SRGB8_ALPHA8 texture of immutable storage (gl::Texture), whose storage
    /// is new whenever `generation` changes; `target`: a framebuffer on the caller's texture, of
    /// the source's size.
    void run(const gl::Texture& source, unsigned generation, const gl::Framebuffer& target, bool swapRedBlue);

private:
    gl::Program program_;
    gl::Program swappedProgram_;
    gl::Sampler nearest_;
    gl::Handle<gl::deleteTexture> view_; ///< GL_RGBA8 view of the source: its bytes undecoded
    unsigned viewOf_ = 0; ///< the generation of the source it views
};

} // namespace defocus
