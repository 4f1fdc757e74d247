// Bokeh sprites: one compute dispatch appends the sprites and counts them into the indirect draw
// command in the same buffer; one instanced draw of quads adds them, blended, to the output.
#include "filter/passes/HighlightSpritePass.hpp"

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
      draw_("highlight_sprite.vert", "highlight_sprite.frag", "highlight sprites: draw"),
      cocParams_(sizeof(CocPass::Uniforms), "highlight sprites coc params"),
      spriteParams_(sizeof(SpriteParams), "highlight sprites params"),
      nearest_(GL_NEAREST, "highlight sprites nearest")
{
}

void HighlightSpritePass::run(const gl::Texture& color, const gl::Texture& depth, const CocCoefficients& k,
                              float highlightGain, float largestColor, float bladeRotationDeg, bool nearField,
                              const gl::StorageBuffer& measurement, std::size_t capacity,
                              const gl::Framebuffer& target)
{
    if (capacity == 0)
        return;
    if (capacity > capacity_) {
        capacity_ = std::bit_ceil(capacity);
        sprites_ = gl::StorageBuffer(static_cast<GLsizeiptr>(kHeaderBytes + capacity_ * kSpriteBytes),
                                     "highlight sprites");
    }
    // 18 vertices: the six triangles of highlight_sprite.vert.
    const std::array<std::uint32_t, 8> header{18, 0, 0, 0, static_cast<std::uint32_t>(capacity_), 0, 0, 0};
    sprites_.update(header.data(), static_cast<GLsizeiptr>(sizeof header));

    CocPass::Uniforms u = CocPass::uniforms(k, false, highlightGain, kThreshold);
    u.largestColor = largestColor;
    cocParams_.update(&u, sizeof u);
    cocParams_.bind(0);
    sprites_.bind(0);
    measurement.bind(1);
    bindTexture(0, color.id(), nearest_.id());
    bindTexture(1, depth.id(), nearest_.id());
    find_.use();
    glDispatchCompute(static_cast<GLuint>((depth.width() + 7) / 8), static_cast<GLuint>((depth.height() + 7) / 8), 1);
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);

    // A corner at 90 degrees + the rotation, counter-clockwise on screen: y runs down the rows.
    const double corner = (90.0 + bladeRotationDeg) * std::numbers::pi / 180.0;
    const SpriteParams params{{static_cast<float>(depth.width()), static_cast<float>(depth.height())},
                              {static_cast<float>(std::cos(corner)), static_cast<float>(-std::sin(corner))},
                              nearField ? 1 : 0,
                              {}};
    spriteParams_.update(&params, sizeof params);
    spriteParams_.bind(1);
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
