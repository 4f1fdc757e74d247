// SPDX-License-Identifier: LGPL-2.1-or-later
// Pass 1: linear colour + signed CoC (pixels) in alpha, into a float target of the frame's size
// or half or a quarter of it. Shader: coc.frag.
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/CocParams.hpp"
#include "filter/passes/TileList.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

class CocPass : public ShadedPass {
public:
    static constexpr const char* kName = "coc";
    CocPass();
    /// `color`: sRGB8 or float RGB; `depth`: R32F metres with no holes; `params`: the frame's
    /// (CocParams: the gather's CoC; its largest colour keeps HDR colour within the target's
    /// range; a highlight gain > 1 scales near-clipped pixels of 8-bit input that get blurred,
    /// coc.frag).
    /// `sizeShift` 1: the target is ((w + 1) / 2, (h + 1) / 2) and each texel averages 2x2 pixels,
    /// its CoC in half-size pixels; 2: ((w + 3) / 4, (h + 3) / 4), 4x4 pixels, quarter-size ones.
    /// A highlight threshold > 0 in `params`: blurred pixels brighter than this that stand out of their tile
    /// keep only that much luminance (their rest goes to bokeh sprites, HighlightSpritePass), and
    /// such pixels in focus (|CoC| < 1 px) enter the blur as what lies round them (standIn() in
    /// highlights.glsl; InFocusLightPass puts the light back);
    /// `neighbourhoods` then holds SceneAnalysis::tileNeighbourhood (highlights.glsl) and `sprites`
    /// the sprites found (HighlightSpritePass::sprites()), whose count says whether they fit.
    /// Either of the two (or `sizeShift` > 0 with `highlightGain` > 1) needs `highlightTiles`,
    /// the tiles of the target (SceneAnalysis::highlightTiles, 16 >> sizeShift texels a side)
    /// that have pixels above the highlight threshold: the pass treats their pixels one by one,
    /// after the plain pass over the whole target.
    void run(const gl::Texture& color, const gl::Texture& depth, const CocParams& params,
             const gl::Framebuffer& target, int sizeShift = 0, const gl::StorageBuffer* neighbourhoods = nullptr,
             const gl::StorageBuffer* sprites = nullptr, const TileList* highlightTiles = nullptr);

private:
    /// The plain variants, full-screen: every pixel of a frame without highlights, and the others'
    /// pixels before their highlight tiles are drawn over.
    gl::Program program_, halfProgram_, quarterProgram_;
    /// On the highlight tiles (tiles.vert). HIGHLIGHTS: pixel by pixel before the mean. SPRITES:
    /// for frames with bokeh sprites (highlightThreshold > 0), a pixel's sprite share (coc.frag),
    /// compiled out of the others, since llvmpipe runs a branch's instructions even where no
    /// pixel takes it. QUARTER_SIZE: never with sprites (makePlan()).
    gl::Program spritesProgram_, halfHighlightsProgram_, halfSpritesProgram_, quarterHighlightsProgram_;
    gl::StorageBuffer noSprites_; ///< bound for the sprite count where there are no sprites
    gl::Sampler nearest_;
    gl::Sampler linear_;
};

} // namespace defocus
