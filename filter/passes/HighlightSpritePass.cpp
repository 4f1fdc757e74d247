// SPDX-License-Identifier: LGPL-2.1-or-later
// Bokeh sprites: three compute dispatches mark the pixels that make a sprite per tile, count
// them into the indirect draw command in the same buffer (empty for a frame over its budget) and
// write them in the order of their tiles and pixels; one instanced draw of hexagons adds them,
// blended, to the output. Nothing comes back to the CPU.
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
// Per tile searched (highlight_sprites.comp's TileSprites): its first sprite, 256 bits of pixels.
constexpr std::size_t kTileBytes = 9 * sizeof(std::uint32_t);

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
    : count_(gl::Program::compute("highlight_sprites.comp", "highlight sprites: count", {"COUNT 1"})),
      settle_(gl::Program::compute("highlight_sprites.comp", "highlight sprites: settle", {"SETTLE 1"})),
      emit_(gl::Program::compute("highlight_sprites.comp", "highlight sprites: emit")),
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
        const auto tileBytes = static_cast<GLsizeiptr>(tiles.size() * kTileBytes);
        if (tileSprites_.size() < tileBytes)
            tileSprites_ = gl::StorageBuffer(static_cast<GLsizeiptr>(std::bit_ceil(static_cast<std::size_t>(tileBytes))),
                                             "highlight sprites: per tile");
        tileSprites_.bind(4);
        count_.use();
        glDispatchCompute(static_cast<GLuint>(tiles.size()), 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        settle_.use();
        glUniform1ui(0, static_cast<GLuint>(tiles.size()));
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        emit_.use();
        glDispatchCompute(static_cast<GLuint>(tiles.size()), 1, 1);
    }
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
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
