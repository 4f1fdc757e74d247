// SPDX-License-Identifier: LGPL-2.1-or-later
// Copies a texture into a target on a set of tiles: in-focus tiles skip the blur. Shader: copy.frag.
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/TileList.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

class CopyPass : public ShadedPass {
public:
    static constexpr const char* kName = "copy";
    CopyPass();
    /// Copies `source` into `target`'s attachments on `tiles`: the first, or with `twoTargets`
    /// both (the rhombus passes' pair of targets).
    void run(const gl::Texture& source, const TileList& tiles, const gl::Framebuffer& target, bool twoTargets = false);

private:
    gl::Program program_;
    gl::Program twoTargetProgram_;
    gl::Sampler nearest_;
};

} // namespace defocus
