// SPDX-License-Identifier: LGPL-2.1-or-later
// Copy pass: copy.frag on the given tiles.
#include "filter/passes/CopyPass.hpp"

#include "filter/passes/Pass.hpp"

namespace defocus {

CopyPass::CopyPass()
    : program_("tiles.vert", "copy.frag", kName),
      twoTargetProgram_("tiles.vert", "copy.frag", "copy two targets", {"TWO_TARGETS 1"}),
      nearest_(GL_NEAREST, "copy nearest")
{
}

void CopyPass::run(const gl::Texture& source, const TileList& tiles, const gl::Framebuffer& target, bool twoTargets)
{
    bindTexture(0, source.id(), nearest_.id());
    shade(twoTargets ? twoTargetProgram_ : program_, target, &tiles);
}

} // namespace defocus
