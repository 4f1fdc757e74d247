// Scene analysis pass: one dispatch, one invocation per tile and eight tiles per work group, then
// one read-back.
#include "filter/passes/SceneAnalysisPass.hpp"

#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "filter/passes/CocPass.hpp"
#include "filter/passes/Pass.hpp"

namespace defocus {

namespace {

// The storage buffer's layout (std430, shaders/scene_measurement.glsl): per tile, min and max
// depth (float bits), the pixels whose |CoC| reaches each histogram edge, highlight pixels,
// pixels, their luminance summed (for the bokeh sprites, which read the buffer on the GPU); the
// word names are the shader's.
constexpr std::size_t kEdges = SceneAnalysis::kHistogramEdges.size();
static_assert(kEdges == 8, "scene_analysis.comp has 8 edges");
constexpr std::size_t kWordsPerTile = 13;
constexpr std::size_t kMinDepthWord = 0, kMaxDepthWord = 1, kFirstReachWord = 2, kHighlightsWord = 10,
                      kPixelsWord = 11;
constexpr GLuint kTilesPerGroup = 8; // local_size_x

} // namespace

SceneAnalysisPass::SceneAnalysisPass()
    : program_(gl::Program::compute("scene_analysis.comp", "scene analysis")),
      eightBitProgram_(gl::Program::compute("scene_analysis.comp", "scene analysis 8-bit", {"EIGHT_BIT 1"})),
      uniforms_(sizeof(CocPass::Uniforms), "scene analysis coc params"),
      nearest_(GL_NEAREST, "scene analysis nearest")
{
}

SceneMeasurement SceneAnalysisPass::run(const gl::Texture& depth, const gl::Texture& color, bool eightBit,
                                        const CocCoefficients& k)
{
    CV_Assert(depth.width() == color.width() && depth.height() == color.height());
    constexpr int T = SceneAnalysis::kTileSize;
    SceneMeasurement m;
    m.tiles = {(depth.width() + T - 1) / T, (depth.height() + T - 1) / T};
    const auto tiles = static_cast<std::size_t>(m.tiles.area());
    const auto bytes = static_cast<GLsizeiptr>(kWordsPerTile * tiles * sizeof(std::uint32_t));
    if (measurement_.size() != bytes)
        measurement_ = gl::StorageBuffer(bytes, "scene measurement");

    const CocPass::Uniforms u = CocPass::uniforms(k, false, 1.0f);
    uniforms_.update(&u, sizeof u);
    uniforms_.bind(0);
    measurement_.bind(0);
    bindTexture(0, depth.id(), nearest_.id());
    bindTexture(1, color.id(), nearest_.id());
    (eightBit ? eightBitProgram_ : program_).use();
    glDispatchCompute((static_cast<GLuint>(m.tiles.width) + kTilesPerGroup - 1) / kTilesPerGroup,
                      static_cast<GLuint>(m.tiles.height), 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);

    std::vector<std::uint32_t> words(kWordsPerTile * tiles);
    measurement_.read(words.data(), bytes);
    m.tileMinDepth.create(m.tiles, CV_32F);
    m.tileMaxDepth.create(m.tiles, CV_32F);
    m.tileHighlights.create(m.tiles, CV_32S);
    std::array<std::size_t, kEdges> reach{};
    for (int y = 0; y < m.tiles.height; ++y)
        for (int x = 0; x < m.tiles.width; ++x) {
            const std::uint32_t* tile =
                words.data() + kWordsPerTile * static_cast<std::size_t>(y * m.tiles.width + x);
            std::memcpy(&m.tileMinDepth.at<float>(y, x), &tile[kMinDepthWord], sizeof(float));
            std::memcpy(&m.tileMaxDepth.at<float>(y, x), &tile[kMaxDepthWord], sizeof(float));
            for (std::size_t i = 0; i < kEdges; ++i)
                reach[i] += tile[kFirstReachWord + i];
            m.highlightPixels += tile[kHighlightsWord];
            m.tileHighlights.at<int>(y, x) = static_cast<int>(tile[kHighlightsWord]);
            m.pixels += tile[kPixelsWord];
        }
    // Bin b holds the pixels that reach edge b - 1 but not edge b.
    std::size_t previous = m.pixels;
    for (std::size_t i = 0; i < kEdges; ++i) {
        m.histogram[i] = static_cast<int>(previous - reach[i]);
        previous = reach[i];
    }
    m.histogram[kEdges] = static_cast<int>(previous);
    return m;
}

} // namespace defocus
