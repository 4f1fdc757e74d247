// SPDX-License-Identifier: LGPL-2.1-or-later
// Upscale (Resolution::Half): the frame-sized result from the half- or quarter-size blur, with the frame's
// own pixels put back where they are in focus. Two draws: the half-size prefilter that keeps the
// interpolation sharp (upscale_prefilter.frag), then the frame-sized upscale (upscale.frag).
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/CocParams.hpp"
#include "filter/passes/TileList.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

class UpscalePass : public ShadedPass {
public:
    static constexpr const char* kName = "upscale";
    static constexpr const char* kPrefilterName = "prefilter";
    UpscalePass();
    /// `color`, `depth`: the frame (as the CoC pass read them); `halfInput`: the half-size CoC
    /// target; `blurred`: the half-size result; `prefiltered`: two half-size targets of the same
    /// format for the prefilter's outputs, S and D (upscale_prefilter.frag). `halfTarget`: the intermediate targets are half
    /// floats (the largest colour kept, as in the CoC pass). Draws into `target`, frame-sized:
    /// the whole of it with the detail, or, with `detailTiles` (FramePlan::detailTiles), the
    /// whole of it with the variant that only interpolates and then those tiles over it with the
    /// detail (on llvmpipe, one full-screen triangle and the few tiles cost less than every
    /// tile drawn with its own variant: 7.7 against 8.6 ms on the TUM clip, 31 % detail tiles).
    struct Io {
        const gl::Texture& color;
        const gl::Texture& depth;
        const gl::Texture& halfInput;
        const gl::Texture& blurred;
        const gl::Texture& sharpened;
        const gl::Texture& added;
        const gl::Framebuffer& prefiltered;
        const gl::Framebuffer& target;
    };
    /// The prefilter (half size, into io.prefiltered), then the upscale (into io.target); the
    /// pipeline times them apart.
    void prefilter(const Io& io);
    /// `params`: the frame's, the CoC pass's (its highlight threshold > 0, on frames with bokeh
    /// sprites, is the cap on a light in focus that the frame's pixels keep here;
    /// InFocusLightPass puts the rest back). `sizeShift`: 1 when the blur ran at half size, 2 at
    /// quarter size.
    void upscale(const Io& io, const CocParams& params, int sizeShift, const TileList* detailTiles = nullptr);

private:
    struct Programs {
        gl::Program full;            ///< the detail, full screen
        gl::Program detailTiles;     ///< the detail, tiles.vert
        gl::Program interpolateOnly; ///< INTERPOLATE_ONLY, full screen
        explicit Programs(int sizeShift);
    };
    Programs half_, quarter_;
    gl::Program prefilter_;
    gl::Sampler nearest_;
    gl::Sampler linear_;
};

} // namespace defocus
