// SPDX-License-Identifier: LGPL-2.1-or-later
// The scene measurement on the GPU, one work group per tile, read back for the plan.
#include "filter/passes/SceneMeasurePass.hpp"

#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "filter/ColorSpace.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

namespace {

/// scene_measure.comp's buffer: a header of counts, then a Tile per tile.
struct Header {
    std::uint32_t invalidPixels;
    std::uint32_t bins[SceneAnalysis::kHistogramEdges.size() + 1];
    std::uint32_t unused[2];
};
struct Tile {
    float minDepth, maxDepth;
    std::uint32_t highlights;
    float luminance;
};
static_assert(sizeof(Header) == 48 && sizeof(Tile) == 16 && sizeof(Header) % sizeof(Tile) == 0);

cv::Size tilesOf(cv::Size frame)
{
    constexpr int T = SceneAnalysis::kTileSize;
    return {(frame.width + T - 1) / T, (frame.height + T - 1) / T};
}

} // namespace

SceneMeasurePass::SceneMeasurePass()
    : program_(gl::Program::compute("scene_measure.comp", "scene measure")),
      eightBitLocation_(program_.uniform("uEightBit")), countHolesLocation_(program_.uniform("uCountHoles")),
      nearest_(GL_NEAREST, "scene measure nearest")
{
    // measureScene()'s decode: the same table, so that the same bytes give the same luminance
    // (a driver's sRGB decode may approximate: llvmpipe's moved tile sums by 1e-3).
    std::array<float, 256> decode{};
    for (std::size_t i = 0; i < decode.size(); ++i)
        decode[i] = srgbToLinear(static_cast<float>(i) / 255.0f);
    glProgramUniform1fv(program_.id(), program_.uniform("uDecode"), static_cast<GLsizei>(decode.size()), decode.data());
}

void SceneMeasurePass::run(const gl::Texture& depth, const gl::Texture& color, bool eightBit,
                           const CocParams& params, const gl::Texture* measured, gl::StorageBuffer& out,
                           gl::ReadbackBuffer& back)
{
    const cv::Size tiles = tilesOf({depth.width(), depth.height()});
    const auto bytes = static_cast<GLsizeiptr>(sizeof(Header) + tiles.area() * sizeof(Tile));
    if (out.size() < bytes)
        out = gl::StorageBuffer(bytes, "scene measurement");
    const Header zero{};
    out.update(&zero, sizeof zero);

    params.bind();
    program_.use();
    glUniform1i(eightBitLocation_, eightBit ? 1 : 0);
    glUniform1i(countHolesLocation_, measured ? 1 : 0);
    bindTexture(0, depth.id(), nearest_.id());
    bindTexture(1, color.id(), nearest_.id());
    bindTexture(2, (measured ? *measured : depth).id(), nearest_.id());
    out.bind(0);
    glDispatchCompute(static_cast<GLuint>(tiles.width), static_cast<GLuint>(tiles.height), 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    if (back.size() < bytes)
        back = gl::ReadbackBuffer(bytes, "scene measurement read");
    back.readBuffer(out.id(), bytes);
}

SceneMeasurement SceneMeasurePass::read(gl::ReadbackBuffer& back, cv::Size frame, bool countedHoles,
                                        std::size_t& invalidPixels)
{
    const cv::Size grid = tilesOf(frame);
    // The header and the tiles in one read (one wait for the GPU), as the shader lays them out.
    std::vector<Tile> words(sizeof(Header) / sizeof(Tile) + static_cast<std::size_t>(grid.area()));
    back.copyTo(words.data(), static_cast<GLsizeiptr>(sizeof(Header) + grid.area() * sizeof(Tile)));
    Header header{};
    std::memcpy(&header, words.data(), sizeof header);
    const Tile* tiles = words.data() + sizeof(Header) / sizeof(Tile);
    invalidPixels = countedHoles ? header.invalidPixels : static_cast<std::size_t>(frame.area());

    SceneMeasurement m;
    m.frame = frame;
    m.tiles = grid;
    m.pixels = static_cast<std::size_t>(frame.area());
    for (std::size_t i = 0; i < m.histogram.size(); ++i)
        m.histogram[i] = static_cast<int>(header.bins[i]);
    m.tileMinDepth.create(grid, CV_32F);
    m.tileMaxDepth.create(grid, CV_32F);
    m.tileHighlights.create(grid, CV_32S);
    m.tileLuminance.create(grid, CV_32F);
    for (int ty = 0, i = 0; ty < grid.height; ++ty)
        for (int tx = 0; tx < grid.width; ++tx, ++i) {
            const Tile& t = tiles[i];
            m.tileMinDepth.at<float>(ty, tx) = t.minDepth;
            m.tileMaxDepth.at<float>(ty, tx) = t.maxDepth;
            m.tileHighlights.at<int>(ty, tx) = static_cast<int>(t.highlights);
            m.tileLuminance.at<float>(ty, tx) = t.luminance;
            m.highlightPixels += t.highlights;
        }
    return m;
}

} // namespace defocus
