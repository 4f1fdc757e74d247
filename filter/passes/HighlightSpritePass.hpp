// Bokeh sprites for highlights: the light of blurred pixels brighter than a threshold, which the
// CoC pass takes out of the gather, scattered as hexagons with exact edges and added to the
// output. Runs only on frames with highlights. Shaders: highlight_sprites.comp (find them, on the
// GPU, into an indirect draw), highlight_sprite.vert/.frag (draw them).
#pragma once

#include <cstddef>

#include "filter/Lens.hpp"
#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class HighlightSpritePass {
public:
    static constexpr const char* kName = "highlights";
    /// Linear luminance above which a blurred pixel's light goes to a sprite: the gather keeps
    /// up to this much of it. 1 = white: float input's HDR lights, 8-bit input's recovered ones.
    static constexpr float kThreshold = 1.0f;

    HighlightSpritePass();
    /// Finds the sprites in `color` (sRGB8 or float RGB) and `depth` (R32F metres, filled) with
    /// the CoC pass' settings (`k`, `highlightGain`, `largestColor`, the scene analysis'
    /// `measurement`), at most `capacity` (the
    /// highlight pixels the scene analysis counted, a superset), and adds them to `target` (the
    /// frame's size, linear or sRGB with GL_FRAMEBUFFER_SRGB) where the gather would have spread
    /// their light (`nearField`: foreground over what is behind it too). A vertex array must be
    /// bound.
    void run(const gl::Texture& color, const gl::Texture& depth, const CocCoefficients& k, float highlightGain,
             float largestColor, float bladeRotationDeg, bool nearField, const gl::StorageBuffer& measurement,
             std::size_t capacity, const gl::Framebuffer& target);

private:
    gl::Program find_, draw_;
    gl::UniformBuffer cocParams_, spriteParams_;
    gl::StorageBuffer sprites_;
    std::size_t capacity_ = 0;
    gl::Sampler nearest_;
};

} // namespace defocus
