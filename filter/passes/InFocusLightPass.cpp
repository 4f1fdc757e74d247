// SPDX-License-Identifier: LGPL-2.1-or-later
// Lights in focus put back: the rhombus blur's lines as uniforms, one program per set of line
// modes, an additive draw on the highlight tiles.
#include "filter/passes/InFocusLightPass.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "filter/passes/Pass.hpp"

namespace defocus {

// The blur reads beyond the frame its edge repeated (RhombusBlurPass); the coverage must read the
// same taps.
InFocusLightPass::InFocusLightPass()
    : uniforms_(sizeof(Uniforms), "lights in focus params"),
      nearest_(GL_NEAREST, "lights in focus nearest", GL_CLAMP_TO_EDGE),
      linear_(GL_LINEAR, "lights in focus linear", GL_CLAMP_TO_EDGE)
{
}

const gl::Program& InFocusLightPass::program(const RhombusBlurPass::Lines& lines)
{
    const auto mode = [](const RhombusBlurPass::Line& line) { return static_cast<int>(line.mode); };
    const int key = mode(lines.x) | mode(lines.z) << 2 | mode(lines.a) << 4 | mode(lines.bOverX) << 6;
    gl::Program& slot = programs_[key];
    if (slot.id() == 0) {
        const std::vector<std::string> defines{
            fmt::format("MODE_X {}", mode(lines.x)), fmt::format("MODE_Z {}", mode(lines.z)),
            fmt::format("MODE_A {}", mode(lines.a)), fmt::format("MODE_B {}", mode(lines.bOverX))};
        slot = gl::Program("tiles.vert", "in_focus_light.frag",
                           fmt::format("lights in focus {}{}{}{}", mode(lines.x), mode(lines.z), mode(lines.a),
                                       mode(lines.bOverX)),
                           defines);
    }
    return slot;
}

void InFocusLightPass::run(const Io& io, const CocParams& params,
                           const RhombusBlurPass::Directions& directions, int taps, int nearTileSize,
                           int blurShift, const TileList& tiles, const gl::Framebuffer& target)
{
    if (tiles.count() == 0)
        return;
    const RhombusBlurPass::Lines lines = RhombusBlurPass::lines(directions, io.coc.width(), io.coc.height());
    Uniforms u{};
    // B's coverage is X's: pass 2 weighs the taps of u3 over X and over Z by X's CoC.
    const RhombusBlurPass::Line* each[4] = {&lines.x, &lines.z, &lines.a, &lines.bOverX};
    for (int i = 0; i < 4; ++i) {
        std::copy_n(each[i]->direction, 2, &u.lines[i][0]);
        std::copy_n(each[i]->across, 2, &u.lines[i][2]);
        u.baseSteps[i] = each[i]->baseStep;
    }
    u.maxTaps = taps;
    u.nearTileSize = nearTileSize;
    u.nearField = io.nearDiameter != nullptr ? 1 : 0;
    u.blurShift = blurShift;
    params.bind();
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(2);
    bindTexture(0, io.color.id(), nearest_.id());
    bindTexture(1, io.depth.id(), nearest_.id());
    if (io.nearDiameter)
        bindTexture(2, io.nearDiameter->id(), nearest_.id());
    bindTexture(3, io.coc.id(), nearest_.id());
    bindTexture(4, io.coc.id(), linear_.id());
    target.bindForDraw();
    program(lines).use();
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    tiles.draw();
    glDisable(GL_BLEND);
}

} // namespace defocus
