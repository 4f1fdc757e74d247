// SPDX-License-Identifier: LGPL-2.1-or-later
// CoC pass: uploads the lens coefficients and draws coc.frag.
#include "filter/passes/CocPass.hpp"

#include <cassert>
#include <cstdint>
#include <limits>

#include "filter/passes/HexBlurPass.hpp"
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
      uniforms_(sizeof(Uniforms), "coc params"),
      noSprites_(8 * sizeof(std::uint32_t), "coc: no sprites"),
      nearest_(GL_NEAREST, "coc nearest"),
      linear_(GL_LINEAR, "coc linear")
{
}

namespace {

// The largest colour a target keeps. Half float: its maximum. Full float: small enough that
// hex_blur.frag's sum of up to kMaxSamples taps cannot overflow to +Inf before it is divided.
constexpr float kLargestHalf = 65504.0f;
constexpr float kLargestFloat = std::numeric_limits<float>::max() / HexBlurPass::kMaxSamples;

} // namespace

float CocPass::largestColor(bool halfTarget)
{
    return halfTarget ? kLargestHalf : kLargestFloat;
}

CocPass::Uniforms CocPass::uniforms(const CocCoefficients& k, bool halfTarget, float highlightGain,
                                    float highlightThreshold)
{
    return {{k.nearScale, k.nearOffset, k.farScale, k.farOffset},
            k.focusM,
            k.maxCocPx,
            k.inverseDepth ? 1 : 0,
            largestColor(halfTarget),
            highlightGain,
            highlightThreshold};
}

void CocPass::run(const gl::Texture& color, const gl::Texture& depth, const CocCoefficients& k, bool halfTarget,
                  const gl::Framebuffer& target, float highlightGain, int sizeShift, float highlightThreshold,
                  const gl::StorageBuffer* neighbourhoods, const gl::StorageBuffer* sprites,
                  const TileList* highlightTiles)
{
    assert(highlightThreshold <= 0.0f || (neighbourhoods && sprites));
    if (neighbourhoods)
        neighbourhoods->bind(1);
    (sprites ? *sprites : noSprites_).bind(2);
    const Uniforms u = uniforms(k, halfTarget, highlightGain, highlightThreshold);
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);
    target.bindForDraw();
    assert(sizeShift >= 0 && sizeShift <= 2);
    bindTexture(0, color.id(), nearest_.id());
    bindTexture(1, depth.id(), nearest_.id());
    bindTexture(2, color.id(), linear_.id());
    (sizeShift == 0 ? program_ : sizeShift == 1 ? halfProgram_ : quarterProgram_).use();
    drawFullscreenTriangle();

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
    (sizeShift == 0   ? spritesProgram_
     : sizeShift == 1 ? (withSprites ? halfSpritesProgram_ : halfHighlightsProgram_)
                      : quarterHighlightsProgram_)
        .use();
    highlightTiles->draw();
}

} // namespace defocus
