// SPDX-License-Identifier: LGPL-2.1-or-later
// Bokeh sprites for highlights: the light of blurred pixels brighter than a threshold, which the
// CoC pass takes out of the gather, scattered in the aperture's shape with exact edges and added to
// the output. Runs only on frames with highlights. Shaders: highlight_sprites.comp (find them, on the
// GPU, into an indirect draw, in an order that does not depend on the GPU's), highlight_sprite.vert/.frag
// (draw them).
#pragma once

#include <cstddef>
#include <vector>

#include <opencv2/core.hpp>

#include "filter/Aperture.hpp"
#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/CocParams.hpp"

namespace defocus {

class HighlightSpritePass {
public:
    static constexpr const char* kName = "highlights";
    /// Linear luminance above which a blurred pixel's light goes to a sprite: the gather keeps
    /// up to this much of it. 1 = white: float input's HDR lights, 8-bit input's recovered ones.
    static constexpr float kThreshold = 1.0f;
    /// Frames whose pixels above white are more than this share of the frame get no sprites at
    /// all, a bound on the pass' cost whatever the picture (highlights.glsl keeps bright tiles
    /// and textures out first). The Blender scene: 1.2 %; the synthetic clips 19 and 38 %.
    static constexpr double kMostHighlightPixels = 0.5;

    HighlightSpritePass();
    /// Step 1, before the CoC pass: finds the sprites in `color` (sRGB8 or float RGB) and `depth`
    /// (R32F metres, filled) with the CoC pass' settings (`params`, the frame's: the gather's CoC,
    /// the highlight gain and threshold, the largest colour; the tiles' `neighbourhoods`,
    /// SceneAnalysis::tileNeighbourhood) and the aperture's (`shape`, whose gatherScale() the
    /// gather's CoC holds, `nearField`), at most `budget` of them;
    /// a frame with more draws none, and the CoC pass (reading sprites()) then keeps all of their
    /// light. Only the 16x16 `tiles` (SceneAnalysis::highlightTiles) are
    /// searched: no pixel elsewhere is bright enough.
    void find(const gl::Texture& color, const gl::Texture& depth, const CocParams& params, const ApertureShape& shape,
              bool nearField, const gl::StorageBuffer& neighbourhoods,
              const std::vector<cv::Point>& tiles, std::size_t budget);
    /// Step 2: adds the sprites found to `target` (the frame's size, linear or sRGB with
    /// GL_FRAMEBUFFER_SRGB) where the gather would have spread their light (with the near field:
    /// foreground over what is behind it too), with find()'s settings; `params` and `depth` are
    /// find()'s. A vertex array must be bound.
    void draw(const CocParams& params, const gl::Texture& depth, const gl::Framebuffer& target);
    /// The sprites and their count, as the GPU holds them (highlight_sprites.comp).
    const gl::StorageBuffer& sprites() const { return sprites_; }

    /// The budget for a frame of `pixels`: one sprite per 64 pixels (4800 at 640x480), so that
    /// the draw's cost stays bounded; the Blender scene makes 279.
    static std::size_t budget(std::size_t pixels, std::size_t highlightPixels);

private:
    /// Fills the SpriteParams block (aperture_sprite.glsl) for a frame of `depth`'s size.
    void updateSpriteParams(const gl::Texture& depth, const ApertureShape& shape, bool nearField);

    gl::Program count_, settle_, emit_, draw_;
    gl::UniformBuffer spriteParams_;
    gl::StorageBuffer sprites_;
    gl::StorageBuffer tiles_; ///< the tiles searched, (column, row) as two ints each
    gl::StorageBuffer tileSprites_; ///< per tile searched: its first sprite, its pixels that make one
    std::size_t capacity_ = 0; ///< sprites the buffer holds
    gl::Sampler nearest_;
};

} // namespace defocus
