// SPDX-License-Identifier: LGPL-2.1-or-later
// One pass of the energy-conserving hexagon: three one-sided rhombi summed (shader
// rhombus_blur.frag, where the decomposition is derived). Two passes and a composite make the
// hexagon; each pass writes two targets.
#pragma once

#include <array>
#include <map>

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/TileList.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

class RhombusBlurPass : public ShadedPass {
public:
    /// Taps per line at most. Lines take one tap per pixel of their length up to `taps`;
    /// longer ones space `taps` taps out evenly.
    static constexpr int kMaxTaps = 64;
    /// The tap count whose programs are compiled up front (the balanced preset's); others
    /// compile on first use.
    static constexpr int kDefaultTaps = 6;
    /// The paper's bleeding rule fades in over this much CoC around its threshold (pixels), so
    /// that it does not switch on depth noise. In pixels, not the paper's unit (a fraction of
    /// the image height): a frame one pixel high would otherwise switch within 0.01 px.
    static constexpr float kBleedingRampPx = 4.0f;

    /// The directions of one hexagon, degrees counter-clockwise on screen: u1 towards the corner
    /// nearest an axis, u2 = u1 + 120, u3 = u1 + 240. `bladeRotationDeg` 0 puts a corner on top
    /// (u1 = 90); 30 a flat edge (u1 = 0). A hexagon squeezed by `squeezeX` and `squeezeY` (each
    /// at most 1: an anamorphic aperture's, gatherSqueeze() in filter/Aperture.hpp) has its
    /// corners along the squeezed directions, `lengths` times as far (pixels per pixel of radius).
    struct Directions {
        float u1, u2, u3;
        float lengths[3] = {1.0f, 1.0f, 1.0f};
    };
    static Directions directions(float bladeRotationDeg, float squeezeX = 1.0f, float squeezeY = 1.0f);

    /// How a line takes its taps (rhombus_lines.glsl): unfiltered, bilinear, or a bilinear pair.
    enum class LineMode { Point = 0, Smooth = 1, Pair = 2 };
    /// One line at a target's size: texture-space offset per pixel of radius along it, half a
    /// pixel across it (Pair lines only, else 0), the step that moves one pixel on its major axis
    /// (pixels of radius: pixels, unless the hexagon is squeezed), and how it takes its taps.
    struct Line {
        float direction[2];
        float across[2];
        float baseStep;
        LineMode mode;
    };
    /// Every line of the two passes for a target of width x height: pass 1's u1 and u2 over the
    /// source (X, Z), pass 2's u2 over X (A), u3 over Z and u3 over X (B, the taps' weights
    /// from X's). InFocusLightPass follows the same lines.
    struct Lines {
        Line x, z, a, bOverZ, bOverX;
    };
    static Lines lines(const Directions& directions, int width, int height);

    /// What a pass reads and writes. Pass 1 reads `sourceA` (the CoC target) and writes X, Z;
    /// pass 2 reads X as `sourceA` and Z as `sourceB` and writes A, B.
    struct Io {
        const gl::Texture& sourceA;
        const gl::Texture* sourceB; ///< pass 2 only
        /// Per tile: the largest foreground CoC diameter that can reach it (pixels, R32F);
        /// nullptr: no near field (lines as long as the centre's own radius).
        const gl::Texture* nearDiameter;
        const gl::Framebuffer& target; ///< two colour attachments (one when fused)
    };

    RhombusBlurPass();
    /// `first`: pass 1 (lines u1 and u2 of the CoC target) or pass 2 (u2 of X, u3 of X and of Z).
    /// `taps`: most taps per line. With `tiles`, only those tiles are drawn. `fused` (pass 2
    /// only): write (A + 2B) / 3, the result, to the target's one attachment instead of A and B.
    /// `unrolled`: the tap loop unrolled to `taps`, faster where most lines are that long
    /// (rhombus_blur.frag).
    void run(const Io& io, bool first, const Directions& directions, int taps, int tileSize,
             const TileList* tiles = nullptr, bool fused = false, bool unrolled = true);

private:
    /// Mirrors the std140 block RhombusBlurParams in rhombus_blur.frag.
    struct Uniforms {
        float directions[4];
        float across[4];
        float baseSteps[2]; ///< std140: the ints follow the vec2 directly
        int nearTileSize;
        float bleedingBias;
        float bleedingMult;
        float cocToPaperUnits;
        float bleedingRamp;
    };
    /// Pass 1: u1 and u2 of the source; pass 2: u2 over X, u3 over Z, u3 over X.
    struct LineModes {
        std::array<LineMode, 2> first;
        std::array<LineMode, 3> second;
    };
    static LineModes lineModes(const Directions& directions);
    /// The program of one variant, compiled on first use: pass, near field, tiles, line modes
    /// (`line3`, u3 over X: pass 2 only; pass 1 programs ignore it). The taps are MAX_TAPS, a
    /// #define of the variant.
    const gl::Program& program(bool first, bool near, bool tiles, LineMode line1, LineMode line2, LineMode line3,
                               int taps, bool fused, bool unrolled);
    std::map<int, gl::Program> programs_;
    gl::UniformBuffer uniforms_;
    gl::Sampler linear_;
    gl::Sampler nearest_;
};

} // namespace defocus
