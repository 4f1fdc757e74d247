// SPDX-License-Identifier: LGPL-2.1-or-later
// The CoC parameters of a frame (the lens' coefficients, the targets' largest colour, the
// highlights' gain and the sprites' threshold): coc_params.glsl's CocParams block in one uniform
// buffer that every pass of the frame reading it binds at binding 0 (the scene measurement, the
// CoC pass, the sprites, the upscale, the light in focus), and the CPU's copy the passes decide
// from. The pipeline keeps one per frame in flight and sets it twice: with the lens alone when
// the frame is begun (the measurement needs no more), with the plan's choices when it is rendered.
#pragma once

#include "filter/Lens.hpp"
#include "filter/gl/Objects.hpp"

namespace defocus {

class CocParams {
public:
    /// Mirrors the std140 block CocParams in coc_params.glsl.
    struct Block {
        float coefficients[4]; ///< nearScale, nearOffset, farScale, farOffset
        float focusM;
        float maxCocPx;
        int inverseDepth;
        float largestColor;
        float highlightGain;
        float highlightThreshold;
    };
    /// The largest colour the passes keep in a half-float or a full-float target.
    static float largestColor(bool halfTarget);
    /// `k`: the gather's CoC; `halfTarget`: RGBA16F targets; `highlightGain` > 1 scales up 8-bit
    /// frames' near-clipped pixels that get blurred; `highlightThreshold` > 0: the luminance above
    /// which a blurred pixel's light goes to a bokeh sprite (0: no sprites).
    static Block block(const CocCoefficients& k, bool halfTarget, float highlightGain = 1.0f,
                       float highlightThreshold = 0.0f);

    /// The buffer, unset until set() (needs a current GL context).
    explicit CocParams(std::string_view label = "coc params");
    /// block(k, halfTarget, highlightGain, highlightThreshold), uploaded.
    void set(const CocCoefficients& k, bool halfTarget, float highlightGain = 1.0f, float highlightThreshold = 0.0f);
    const Block& values() const { return values_; }
    /// At binding 0, where coc_params.glsl reads it.
    void bind() const { buffer_.bind(0); }

private:
    gl::UniformBuffer buffer_;
    Block values_{};
};

} // namespace defocus
