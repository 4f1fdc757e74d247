// SPDX-License-Identifier: LGPL-2.1-or-later
// CoC pass: binds the frame's CoC parameters and draws coc.frag.
#include "filter/passes/CocPass.hpp"

#include <cassert>
#include <cstdint>

#include "filter/passes/Pass.hpp"

namespace defocus {

CocPass::CocPass()
    : program_("fullscreen.vert", "coc.frag", kName),
      halfProgram_("fullscreen.vert", "coc.frag", "coc half size", {"HALF_SIZE 1"}),
      quarterProgram_("fullscreen.vert", "coc.frag", "coc quarter size", {"QUARTER_SIZE 1"}),
      spritesProgram_("tiles.vert", "coc.frag", "coc sprites", {"SPRITES 1"}),
      halfHighlightsProgram_("tiles.vert", "coc.frag", "coc half size highlights", {"HALF_SIZE 1", "HIGHLIGHTS 1"}),
      halfSpritesProgram_("tiles.vert", "coc.frag", "coc half size sprites", {"HALF_SIZE 1", "HIGHLIGHTS 1", "SPRITES 1"}),
      quarterHighlightsProgram_("tiles.vert", "coc.frag", "coc quarter size highlights",
                                {"QUARTER_SIZE 1", "HIGHLIGHTS 1"}),
      noSprites_(8 * sizeof(std::uint32_t), "coc: no sprites"),
      nearest_(GL_NEAREST, "coc nearest"),
      linear_(GL_LINEAR, "coc linear")
{
}

void CocPass::run(const gl::Texture& color, const gl::Texture& depth, const CocParams& params,
                  const gl::Framebuffer& target, int sizeShift, const gl::StorageBuffer* neighbourhoods,
                  const gl::StorageBuffer* sprites, const TileList* highlightTiles)
{
    const float highlightThreshold = params.values().highlightThreshold;
    const float highlightGain = params.values().highlightGain;
    assert(highlightThreshold <= 0.0f || (neighbourhoods && sprites));
    if (neighbourhoods)
        neighbourhoods->bind(1);
    (sprites ? *sprites : noSprites_).bind(2);
    params.bind();
    assert(sizeShift >= 0 && sizeShift <= 2);
    bindTexture(0, color.id(), nearest_.id());
    bindTexture(1, depth.id(), nearest_.id());
    bindTexture(2, color.id(), linear_.id());
    shade(sizeShift == 0 ? program_ : sizeShift == 1 ? halfProgram_ : quarterProgram_, target);

    // Highlights are treated pixel by pixel (at half size, four fetches instead of one mean),
    // only on the tiles that have them: elsewhere recovery leaves a pixel as it is and no pixel is
    // bright enough for a sprite, so the plain pass' texels stand (up to the rounding of their
    // mean). At full size the plain pass recovers highlights itself.
    const bool withSprites = highlightThreshold > 0.0f;
    if (!withSprites && (highlightGain <= 1.0f || sizeShift == 0))
        return;
    assert(highlightTiles);
    // Quarter size is chosen only on frames without sprites (makePlan()).
    assert(sizeShift < 2 || !withSprites);
    if (highlightTiles->count() == 0)
        return;
    shade(sizeShift == 0   ? spritesProgram_
          : sizeShift == 1 ? (withSprites ? halfSpritesProgram_ : halfHighlightsProgram_)
                           : quarterHighlightsProgram_,
          target, highlightTiles);
}

} // namespace defocus
