// SPDX-License-Identifier: LGPL-2.1-or-later
// Bokeh sprites: one compute dispatch appends the sprites and counts them into the indirect draw
// command in the same buffer, a second of one invocation empties the draw of a frame over its
// budget, the CPU puts them in the order of their pixels; one instanced draw of hexagons adds
// them, blended, to the output.
#include "filter/passes/HighlightSpritePass.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <vector>

#include "filter/passes/CocPass.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

namespace {

// The buffer (highlight_sprites.comp): the indirect command (18 vertices, the sprite count as
// instances), the capacity, padding, then two vec4 per sprite.
constexpr std::size_t kHeaderBytes = 8 * sizeof(std::uint32_t);
constexpr std::size_t kSpriteBytes = 8 * sizeof(float);

/// Mirrors the std140 block SpriteParams in aperture_sprite.glsl.
struct SpriteParams {
    float frameSize[2];
    float ratio;
    int edgeCount;
    int nearField;
    float gatherScale;
    float fanScale;
    float fanMargin;
    float fanCorner[2];
    float unitArea;
    float unused;
    float edges[4 * 16];
};
static_assert(offsetof(SpriteParams, fanCorner) == 32 && offsetof(SpriteParams, edges) == 48);

} // namespace

HighlightSpritePass::HighlightSpritePass()
    : find_(gl::Program::compute("highlight_sprites.comp", "highlight sprites: find")),
      settle_(gl::Program::compute("highlight_sprites.comp", "highlight sprites: settle", {"SETTLE 1"})),
      draw_("highlight_sprite.vert", "highlight_sprite.frag", "highlight sprites: draw"),
      spriteParams_(sizeof(SpriteParams), "highlight sprites params"),
      sprites_(static_cast<GLsizeiptr>(kHeaderBytes + kSpriteBytes), "highlight sprites"),
      capacity_(1),
      nearest_(GL_NEAREST, "highlight sprites nearest")
{
}

void HighlightSpritePass::updateSpriteParams(const gl::Texture& depth, const ApertureShape& shape, bool nearField)
{
    const ApertureEdges edges = apertureEdges(shape);
    SpriteParams params{};
    params.frameSize[0] = static_cast<float>(depth.width());
    params.frameSize[1] = static_cast<float>(depth.height());
    params.ratio = shape.ratio;
    params.edgeCount = edges.count;
    params.nearField = nearField ? 1 : 0;
    params.gatherScale = gatherScale(shape);
    params.unitArea = static_cast<float>(apertureArea(shape));
    std::copy(edges.edges.begin(), edges.edges.end(), params.edges);
    // The fan (highlight_sprite.vert): the hexagon's own corners 0.81 px out, a corner at 90
    // degrees + the rotation, counter-clockwise on screen (y runs down the rows); for other
    // shapes the hexagon around the circle 0.71 px beyond their circumradius (that much
    // further where the squeeze widens them), corner up.
    const double corner =
        shape.isHexagon() ? (90.0 + shape.rotationDeg) * std::numbers::pi / 180.0 : std::numbers::pi / 2;
    params.fanCorner[0] = static_cast<float>(std::cos(corner));
    params.fanCorner[1] = static_cast<float>(-std::sin(corner));
    const float toCorner = shape.isHexagon() ? 1.0f : 1.0f / std::cos(static_cast<float>(std::numbers::pi) / 6.0f);
    params.fanScale = toCorner;
    params.fanMargin = shape.isHexagon() ? 0.81f : 0.71f * std::max(shape.ratio, 1.0f) * toCorner;
    spriteParams_.update(&params, sizeof params);
}

std::size_t HighlightSpritePass::budget(std::size_t pixels, std::size_t highlightPixels)
{
    return std::max<std::size_t>(1, std::min(pixels / 64, highlightPixels));
}

void HighlightSpritePass::find(const gl::Texture& color, const gl::Texture& depth, const CocParams& params,
                               const ApertureShape& shape, bool nearField, const gl::StorageBuffer& neighbourhoods, const std::vector<cv::Point>& tiles,
                               std::size_t budget)
{
    if (budget > capacity_) {
        capacity_ = std::bit_ceil(budget);
        sprites_ = gl::StorageBuffer(static_cast<GLsizeiptr>(kHeaderBytes + capacity_ * kSpriteBytes),
                                     "highlight sprites");
    }
    // 18 vertices: the six triangles of highlight_sprite.vert; no instance yet; the budget.
    const std::array<std::uint32_t, 8> header{18, 0, 0, 0, static_cast<std::uint32_t>(budget), 0, 0, 0};
    sprites_.update(header.data(), static_cast<GLsizeiptr>(sizeof header));

    assert(params.values().highlightThreshold == kThreshold);
    params.bind();
    sprites_.bind(0);
    neighbourhoods.bind(1);
    bindTexture(0, color.id(), nearest_.id());
    bindTexture(1, depth.id(), nearest_.id());
    updateSpriteParams(depth, shape, nearField);
    spriteParams_.bind(1);
    if (!tiles.empty()) {
        static_assert(sizeof(cv::Point) == 2 * sizeof(std::int32_t));
        const auto bytes = static_cast<GLsizeiptr>(tiles.size() * sizeof(cv::Point));
        if (tiles_.size() < bytes)
            tiles_ = gl::StorageBuffer(static_cast<GLsizeiptr>(std::bit_ceil(static_cast<std::size_t>(bytes))),
                                       "highlight sprites: tiles searched");
        tiles_.update(tiles.data(), bytes);
        tiles_.bind(3);
        find_.use();
        glDispatchCompute(static_cast<GLuint>(tiles.size()), 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    settle_.use();
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);

    // The search appends sprites in whatever order its invocations run, and the draw adds them
    // in that order: where sprites overlap, float sums (and an sRGB8 target's rounding after each
    // one) then differed from run to run by an 8-bit step. In the order of their pixels the same
    // frame gives the same bits every time (AdaptivePlanGLTest). Each sprite is one texel, so
    // its position orders it.
    std::array<std::uint32_t, 8> read{};
    glGetNamedBufferSubData(sprites_.id(), 0, static_cast<GLsizeiptr>(sizeof read), read.data());
    const std::size_t count = read[1] / 4; // four instances per sprite
    if (count > 1) {
        std::vector<std::array<float, 8>> list(count);
        const auto bytes = static_cast<GLsizeiptr>(count * kSpriteBytes);
        glGetNamedBufferSubData(sprites_.id(), static_cast<GLintptr>(kHeaderBytes), bytes, list.data());
        std::sort(list.begin(), list.end(), [](const std::array<float, 8>& a, const std::array<float, 8>& b) {
            return a[1] < b[1] || (a[1] == b[1] && a[0] < b[0]);
        });
        glNamedBufferSubData(sprites_.id(), static_cast<GLintptr>(kHeaderBytes), bytes, list.data());
    }
}

void HighlightSpritePass::draw(const CocParams& params, const gl::Texture& depth, const gl::Framebuffer& target)
{
    // The sprite parameters are the frame's, as find() left them.
    params.bind();
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
