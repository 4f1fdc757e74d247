// SPDX-License-Identifier: LGPL-2.1-or-later
// Rhombus blur pass: per-pass line directions in texture space, the bleeding constants shared
// with the McIntosh blur, and the two-target draw.
#include "filter/passes/RhombusBlurPass.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "filter/passes/HexBlurPass.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

namespace {

/// One pixel along `degrees` in texture coordinates (rows run top to bottom, so a
/// counter-clockwise screen angle moves towards smaller v; see HexBlurPass::offsets), and the
/// length in pixels of the step that moves one whole pixel along the major axis.
void step(float degrees, int width, int height, float* out, float& baseStep)
{
    const double angle = degrees * std::numbers::pi / 180.0;
    out[0] = static_cast<float>(std::cos(angle) / width);
    out[1] = static_cast<float>(-std::sin(angle) / height);
    baseStep = static_cast<float>(1.0 / std::max(std::abs(std::cos(angle)), std::abs(std::sin(angle))));
}

/// Half a pixel perpendicular to `degrees`, in texture coordinates.
void halfPixelAcross(float degrees, int width, int height, float* out)
{
    const double angle = degrees * std::numbers::pi / 180.0;
    out[0] = static_cast<float>(-0.5 * std::sin(angle) / width);
    out[1] = static_cast<float>(-0.5 * std::cos(angle) / height);
}

bool alongAxis(float degrees)
{
    return std::abs(std::remainder(static_cast<double>(degrees), 90.0)) < 1e-4;
}

} // namespace

/// The tap modes of each line. A line crossed later by a line along another off-axis direction
/// must be smooth (bilinear); a line crossing such a line takes the bilinear pair
/// (rhombus_blur.frag). Lines on an axis, and lines crossing only an axis line, are exact with
/// unfiltered taps, but for u3 over X: with u1 on an axis, bilinear taps there make the seams
/// where its rhombus meets the third one's (whose pair of taps softens its edges) match better.
RhombusBlurPass::LineModes RhombusBlurPass::lineModes(const Directions& d)
{
    const bool axis1 = alongAxis(d.u1), axis2 = alongAxis(d.u2), axis3 = alongAxis(d.u3);
    return {
        {
            axis1 ? LineMode::Point : LineMode::Smooth, // u1 of the source: X, crossed by u2 and u3
            axis2 ? LineMode::Point : LineMode::Smooth, // u2 of the source: Z, crossed by u3
        },
        {
            axis1 || axis2 ? LineMode::Point : LineMode::Pair,                                 // u2 over X
            axis2 || axis3 ? LineMode::Point : LineMode::Pair,                                 // u3 over Z
            axis3 ? LineMode::Point : (axis1 ? LineMode::Smooth : LineMode::Pair),             // u3 over X
        },
    };
}

// Taps beyond the frame read its edge pixels repeated: the scene goes on beyond the frame as it
// is at the edge. Read mirrored instead (chosen first, on the Blender scene alone), a gradient
// into the edge turned back and a structure along it (a wall's mortar line in the edge row) was
// reflected away; on the corpus the 8 px next to the edges measured better repeated on eight
// scenes of nine (near-object 25.1 -> 39.3 dB high, spheres-near-focus 38.6 -> 43.8,
// overlapping-lights 21.9 -> 24.6), worse on the Blender scene (32.4 -> 30.5), and the
// corpus's minimum and median rose for every preset (docs/accuracy.md).
RhombusBlurPass::RhombusBlurPass()
    : uniforms_(sizeof(Uniforms), "rhombus blur params"),
      linear_(GL_LINEAR, "rhombus blur linear", GL_CLAMP_TO_EDGE),
      nearest_(GL_NEAREST, "rhombus blur nearest", GL_CLAMP_TO_EDGE)
{
    // The variants of the default rotation (a corner on top), so that no frame pays for them.
    const LineModes modes = lineModes(directions(0.0f));
    for (const bool first : {true, false})
        for (const bool near : {false, true})
            for (const bool tiles : {false, true})
                for (const bool fused : {false, true})
                    for (const bool unrolled : {false, true})
                        if (!(first && fused))
                            program(first, near, tiles, first ? modes.first[0] : modes.second[0],
                                    first ? modes.first[1] : modes.second[1], modes.second[2], kDefaultTaps, fused,
                                    unrolled);
}

const gl::Program& RhombusBlurPass::program(bool first, bool near, bool tiles, LineMode line1, LineMode line2,
                                            LineMode line3, int taps, bool fused, bool unrolled)
{
    if (first)
        line3 = LineMode::Point; // pass 1 has no third line: one program whatever the caller passed
    const int key = (first ? 1 : 0) | (near ? 2 : 0) | (tiles ? 4 : 0) | static_cast<int>(line1) << 3 |
                    static_cast<int>(line2) << 5 | (fused ? 1 << 7 : 0) | taps << 8 | static_cast<int>(line3) << 16 |
                    (unrolled ? 1 << 18 : 0);
    gl::Program& slot = programs_[key];
    if (slot.id() == 0) {
        std::vector<std::string> defines{fmt::format("LINE1_MODE {}", static_cast<int>(line1)),
                                         fmt::format("LINE2_MODE {}", static_cast<int>(line2)),
                                         fmt::format("MAX_TAPS {}", taps)};
        if (first)
            defines.emplace_back("FIRST_PASS 1");
        else
            defines.emplace_back(fmt::format("LINE3_MODE {}", static_cast<int>(line3)));
        if (near)
            defines.emplace_back("NEAR_FIELD 1");
        if (fused)
            defines.emplace_back("FUSED 1");
        if (unrolled)
            defines.emplace_back("UNROLLED 1");
        const std::string name = fmt::format("rhombus_blur{}{}{}{} {}{}{} x{}{}", first ? " first" : " second",
                                             fused ? " fused" : "", near ? " near" : "", tiles ? " tiles" : "",
                                             static_cast<int>(line1), static_cast<int>(line2),
                                             first ? std::string() : std::to_string(static_cast<int>(line3)), taps,
                                             unrolled ? " unrolled" : "");
        slot = gl::Program(tiles ? "tiles.vert" : "fullscreen.vert", "rhombus_blur.frag", name, defines);
    }
    return slot;
}

RhombusBlurPass::Directions RhombusBlurPass::directions(float bladeRotationDeg, float squeezeX, float squeezeY)
{
    // Any corner can be u1 (the three rhombi from alternate corners cover the same hexagon):
    // take the one nearest an axis, so that at rotations in steps of 30 deg the first line is
    // exact and only the third rhombus crosses one off-axis line with another.
    float u1 = 90.0f + bladeRotationDeg;
    double best = 90.0;
    for (int k = 0; k < 6; ++k) {
        const float corner = 90.0f + bladeRotationDeg + 60.0f * static_cast<float>(k);
        const double offAxis = std::abs(std::remainder(static_cast<double>(corner), 90.0));
        if (offAxis < best - 1e-6) {
            best = offAxis;
            u1 = corner;
        }
    }
    Directions d{u1, u1 + 120.0f, u1 + 240.0f};
    if (squeezeX == 1.0f && squeezeY == 1.0f)
        return d;
    // Squeezed, a corner at angle a moves to (squeezeX cos a, squeezeY sin a): the rhombi spanned
    // by the squeezed corners make the squeezed hexagon, and each line runs that far along its
    // new direction per pixel of radius. An axis stays an axis.
    float* corners[] = {&d.u1, &d.u2, &d.u3};
    for (int k = 0; k < 3; ++k) {
        const double a = *corners[k] * std::numbers::pi / 180.0;
        const double x = squeezeX * std::cos(a), y = squeezeY * std::sin(a);
        d.lengths[k] = static_cast<float>(std::hypot(x, y));
        *corners[k] = static_cast<float>(std::atan2(y, x) * 180.0 / std::numbers::pi);
    }
    return d;
}

RhombusBlurPass::Lines RhombusBlurPass::lines(const Directions& d, int width, int height)
{
    const LineModes modes = lineModes(d);
    const float angles[] = {d.u1, d.u2, d.u3};
    const auto line = [&](int corner, LineMode mode, bool pair) {
        const float degrees = angles[corner];
        Line l{};
        step(degrees, width, height, l.direction, l.baseStep);
        // A squeezed corner: the line moves lengths[corner] pixels per pixel of radius.
        l.direction[0] *= d.lengths[corner];
        l.direction[1] *= d.lengths[corner];
        l.baseStep /= d.lengths[corner];
        if (pair)
            halfPixelAcross(degrees, width, height, l.across);
        l.mode = mode;
        return l;
    };
    // u3's two lines share their offsets: either one taking pairs sets them for both.
    const bool u3Pair = modes.second[1] == LineMode::Pair || modes.second[2] == LineMode::Pair;
    return {line(0, modes.first[0], modes.first[0] == LineMode::Pair),
            line(1, modes.first[1], modes.first[1] == LineMode::Pair),
            line(1, modes.second[0], modes.second[0] == LineMode::Pair),
            line(2, modes.second[1], u3Pair),
            line(2, modes.second[2], u3Pair)};
}

void RhombusBlurPass::run(const Io& io, bool first, const Directions& d, int taps, int tileSize,
                          const TileList* tiles, bool fused, bool unrolled)
{
    assert(taps >= 1 && taps <= kMaxTaps);
    assert(first || io.sourceB);
    assert(!(first && fused));
    const Lines all = lines(d, io.target.width(), io.target.height());
    const Line& line1 = first ? all.x : all.a;
    const Line& line2 = first ? all.z : all.bOverZ;
    const LineMode mode3 = all.bOverX.mode; // pass 2: u3 over X, the same direction as line 2
    Uniforms u{};
    std::copy_n(line1.direction, 2, &u.directions[0]);
    std::copy_n(line2.direction, 2, &u.directions[2]);
    std::copy_n(line1.across, 2, &u.across[0]);
    std::copy_n(line2.across, 2, &u.across[2]);
    u.baseSteps[0] = line1.baseStep;
    u.baseSteps[1] = line2.baseStep;
    const LineMode mode1 = line1.mode, mode2 = line2.mode;
    const int height = io.target.height();
    u.nearTileSize = tileSize;
    u.bleedingBias = HexBlurPass::kBleedingBias;
    u.bleedingMult = HexBlurPass::kBleedingMult;
    u.cocToPaperUnits = 1.0f / static_cast<float>(height);
    u.bleedingRamp = kBleedingRampPx * u.cocToPaperUnits;
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);

    const gl::Texture& second = first ? io.sourceA : *io.sourceB;
    bindTexture(0, io.sourceA.id(), nearest_.id());
    bindTexture(1, io.sourceA.id(), linear_.id());
    bindTexture(3, second.id(), nearest_.id());
    bindTexture(4, second.id(), linear_.id());
    if (io.nearDiameter)
        bindTexture(2, io.nearDiameter->id(), nearest_.id());
    shade(program(first, io.nearDiameter != nullptr, tiles != nullptr, mode1, mode2, mode3, taps, fused, unrolled),
          io.target, tiles);
}

} // namespace defocus
