// Bokeh sprites: one compute dispatch appends the sprites and counts them into the indirect draw
// command in the same buffer, a second of one invocation empties the draw of a frame over its
// budget; one instanced draw of hexagons adds them, blended, to the output.
#include "filter/passes/HighlightSpritePass.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "filter/passes/CocPass.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

namespace {

// The buffer (highlight_sprites.comp): the indirect command (18 vertices, the sprite count as
// instances), the capacity, padding, then two vec4 per sprite.
constexpr std::size_t kHeaderBytes = 8 * sizeof(std::uint32_t);
constexpr std::size_t kSpriteBytes = 8 * sizeof(float);

/// Mirrors the std140 block SpriteParams in hexagon_sprite.glsl.
struct SpriteParams {
    float frameSize[2];
    float corner[2];
    int nearField;
    int pad[3];
};

} // namespace

HighlightSpritePass::HighlightSpritePass()
    : find_(gl::Program::compute("highlight_sprites.comp", "highlight sprites: find")),
      settle_(gl::Program::compute("highlight_sprites.comp", "highlight sprites: settle", {"SETTLE 1"})),
      draw_("highlight_sprite.vert", "highlight_sprite.frag", "highlight sprites: draw"),
      cocParams_(sizeof(CocPass::Uniforms), "highlight sprites coc params"),
      spriteParams_(sizeof(SpriteParams), "highlight sprites params"),
      sprites_(static_cast<GLsizeiptr>(kHeaderBytes + kSpriteBytes), "highlight sprites"),
      capacity_(1),
      nearest_(GL_NEAREST, "highlight sprites nearest")
{
}

void HighlightSpritePass::updateSpriteParams(const gl::Texture& depth, float bladeRotationDeg, bool nearField)
{
    // A corner at 90 degrees + the rotation, counter-clockwise on screen: y runs down the rows.
    const double corner = (90.0 + bladeRotationDeg) * std::numbers::pi / 180.0;
    const SpriteParams params{{static_cast<float>(depth.width()), static_cast<float>(depth.height())},
                              {static_cast<float>(std::cos(corner)), static_cast<float>(-std::sin(corner))},
                              nearField ? 1 : 0,
                              {}};
    spriteParams_.update(&params, sizeof params);
}

std::size_t HighlightSpritePass::budget(std::size_t pixels, std::size_t highlightPixels)
{
    return std::max<std::size_t>(1, std::min(pixels / 64, highlightPixels));
}

void HighlightSpritePass::find(const gl::Texture& color, const gl::Texture& depth, const CocCoefficients& k,
                               float highlightGain, float largestColor, float bladeRotationDeg, bool nearField,
                               const gl::StorageBuffer& measurement, std::size_t budget)
{
    if (budget > capacity_) {
        capacity_ = std::bit_ceil(budget);
        sprites_ = gl::StorageBuffer(static_cast<GLsizeiptr>(kHeaderBytes + capacity_ * kSpriteBytes),
                                     "highlight sprites");
    }
    // 18 vertices: the six triangles of highlight_sprite.vert; no instance yet; the budget.
    const std::array<std::uint32_t, 8> header{18, 0, 0, 0, static_cast<std::uint32_t>(budget), 0, 0, 0};
    sprites_.update(header.data(), static_cast<GLsizeiptr>(sizeof header));

    CocPass::Uniforms u = CocPass::uniforms(k, false, highlightGain, kThreshold);
    u.largestColor = largestColor;
    cocParams_.update(&u, sizeof u);
    cocParams_.bind(0);
    sprites_.bind(0);
    measurement.bind(1);
    bindTexture(0, color.id(), nearest_.id());
    bindTexture(1, depth.id(), nearest_.id());
    updateSpriteParams(depth, bladeRotationDeg, nearField);
    spriteParams_.bind(1);
    find_.use();
    glDispatchCompute(static_cast<GLuint>((depth.width() + 7) / 8), static_cast<GLuint>((depth.height() + 7) / 8), 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    settle_.use();
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
}

void HighlightSpritePass::draw(const gl::Texture& depth, const gl::Framebuffer& target)
{
    // The CoC and sprite parameters are the frame's, as find() left them.
    cocParams_.bind(0);
    spriteParams_.bind(1);
    sprites_.bind(0);
    bindTexture(1, depth.id(), nearest_.id());
    target.bindForDraw();
    draw_.use();
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, sprites_.id());
    glDrawArraysIndirect(GL_TRIANGLES, nullptr);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    glDisable(GL_BLEND);
}

} // namespace defocus
