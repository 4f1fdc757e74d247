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

RhombusBlurPass::RhombusBlurPass()
    : uniforms_(sizeof(Uniforms), "rhombus blur params"),
      linear_(GL_LINEAR, "rhombus blur linear"),
      nearest_(GL_NEAREST, "rhombus blur nearest")
{
    for (const bool first : {false, true})
        for (const bool near : {false, true})
            for (const bool tiles : {false, true}) {
                std::vector<std::string> defines;
                if (first)
                    defines.emplace_back("FIRST_PASS 1");
                if (near)
                    defines.emplace_back("NEAR_FIELD 1");
                const std::string name = fmt::format("rhombus_blur{}{}{}", first ? " first" : " second",
                                                     near ? " near" : "", tiles ? " tiles" : "");
                programs_[first][near][tiles] =
                    gl::Program(tiles ? "tiles.vert" : "fullscreen.vert", "rhombus_blur.frag", name, defines);
            }
}

RhombusBlurPass::Directions RhombusBlurPass::directions(float bladeRotationDeg)
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
    return {u1, u1 + 120.0f, u1 + 240.0f};
}

void RhombusBlurPass::run(const Io& io, bool first, const Directions& d, int taps, int tileSize,
                          const TileList* tiles)
{
    assert(taps >= 1 && taps <= kMaxTaps);
    assert(first || io.sourceB);
    const int width = io.target.width(), height = io.target.height();
    const float line1 = first ? d.u1 : d.u2, line2 = first ? d.u2 : d.u3;
    Uniforms u{};
    step(line1, width, height, &u.directions[0], u.baseSteps[0]);
    step(line2, width, height, &u.directions[2], u.baseSteps[1]);
    // Which lines need filtered taps. A line crossed later by a line along another off-axis
    // direction must be smooth (bilinear); a line crossing such a line needs bilinear taps and
    // the pair across it (rhombus_blur.frag). Lines on an axis, and lines crossing an axis line,
    // are exact with unfiltered taps, which on llvmpipe cost a quarter of a bilinear one.
    const bool axis1 = alongAxis(d.u1), axis2 = alongAxis(d.u2), axis3 = alongAxis(d.u3);
    bool smooth1 = false, smooth2 = false;
    if (first) {
        smooth1 = !axis1; // X: crossed by u2 and u3
        smooth2 = !axis2; // u2 in Y: crossed by u3
    } else {
        smooth1 = !(axis1 || axis2); // u2 over X
        smooth2 = !axis3;            // u3 over Y, which holds lines along u1 and u2
        if (smooth1)
            halfPixelAcross(line1, width, height, &u.across[0]);
        if (smooth2 && !(axis1 && axis2))
            halfPixelAcross(line2, width, height, &u.across[2]);
    }
    u.maxTaps = taps;
    u.nearTileSize = tileSize;
    u.bleedingBias = HexBlurPass::kBleedingBias;
    u.bleedingMult = HexBlurPass::kBleedingMult;
    u.cocToPaperUnits = 1.0f / static_cast<float>(height);
    u.bleedingRamp = kBleedingRampPx * u.cocToPaperUnits;
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);

    io.target.bindForDraw();
    const gl::Texture& second = first ? io.sourceA : *io.sourceB;
    bindTexture(0, io.sourceA.id(), (smooth1 ? linear_ : nearest_).id());
    bindTexture(1, io.sourceA.id(), linear_.id());
    bindTexture(3, second.id(), (smooth2 ? linear_ : nearest_).id());
    bindTexture(4, second.id(), linear_.id());
    if (io.nearDiameter)
        bindTexture(2, io.nearDiameter->id(), nearest_.id());
    programs_[first][io.nearDiameter != nullptr][tiles != nullptr].use();
    if (tiles)
        tiles->draw();
    else
        drawFullscreenTriangle();
}

} // namespace defocus
