// SPDX-License-Identifier: LGPL-2.1-or-later
// What a frame calls for: per-tile CoC range, a CoC histogram, foreground blur, highlights and
// holes, measured from the frame and its filled depth (on the GPU by SceneMeasurePass, or on the
// CPU by measureScene()). The plan made from it decides which passes run where.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "filter/Lens.hpp"

namespace defocus {

/// Resolution::Half: the upscale (upscale.frag) puts the frame's own pixels back under this
/// |CoC|, fully up to half of it and fading out to it. At quarter size twice that
/// (upscaleDetailBelowPx()): below 4 px a quarter-size blur leaves its pixels alone.
inline constexpr float kUpscaleDetailBelowPx = 2.0f;

/// The upscale's detail limit for blurs at 1 / 2^blurShift of the frame's size (blurShift 1 or 2).
inline float upscaleDetailBelowPx(int blurShift)
{
    return kUpscaleDetailBelowPx * static_cast<float>(1 << (blurShift - 1));
}

/// quarterOnLargeBlur: a frame goes to quarter size when more than this share of its blurred
/// pixels (|CoC| >= 1 px) have |CoC| >= kQuarterCocPx (see makePlan()).
inline constexpr float kQuarterCocPx = 32.0f;
inline constexpr double kQuarterShare = 0.1;

struct SceneAnalysis {
    static constexpr int kTileSize = 16; ///< pixels per tile side
    /// Upper edges of the |CoC| histogram bins, pixels; the last bin takes the rest.
    static constexpr std::array<float, 8> kHistogramEdges{0.5f, 1.f, 2.f, 4.f, 8.f, 16.f, 32.f, 64.f};

    cv::Size tiles;            ///< tile grid size (ceil(width / 16) x ceil(height / 16))
    cv::Mat tileMinCoc;        ///< CV_32FC1 per tile: smallest signed CoC (pixels)
    cv::Mat tileMaxCoc;        ///< CV_32FC1 per tile: largest signed CoC (pixels)
    float minCoc = 0.0f;       ///< whole frame, signed pixels
    float maxCoc = 0.0f;
    std::array<int, kHistogramEdges.size() + 1> histogram{}; ///< pixel counts per |CoC| bin
    bool foreground = false;   ///< some pixel is blurred in front of the focus plane (CoC <= -0.5)
    /// CV_32FC1 per tile: the largest foreground CoC diameter (pixels) whose blur can reach the
    /// tile, i.e. the tiles' foreground maxima dilated by the reach of the largest one.
    cv::Mat tileNearDiameter;
    double highlightFraction = 0.0; ///< pixels above the highlight threshold
    std::size_t highlightPixels = 0; ///< the same, counted
    /// The tiles (column, row) with a pixel above the highlight threshold: the only ones where
    /// the CoC pass treats pixels one by one (highlight recovery, the bokeh sprites' share) and
    /// where sprites are looked for.
    std::vector<cv::Point> highlightTiles;
    /// Frames with highlights: CV_32FC4 per tile, over the 3x3 tiles around it (clamped to the
    /// frame): their pixels, highlight pixels and summed luminance, and 0. The bokeh sprites judge
    /// a light against it (highlights.glsl); empty without highlights.
    cv::Mat tileNeighbourhood;
    double invalidDepthFraction = 0.0;

    /// Largest |CoC| of the frame.
    float maxAbsCoc() const;
    /// Every |CoC| under half a pixel: nothing to blur (FramePlan::allInFocus).
    bool allInFocus() const { return maxAbsCoc() < 0.5f; }
    /// Some pixel above the highlight threshold (FramePlan::highlights).
    bool hasHighlights() const { return highlightFraction > 0.0; }
    /// |CoC| of the tile at (x, y) reaches `sharpBelowPx` somewhere (the blur's in-focus limit).
    bool tileNeedsBlur(int x, int y, float sharpBelowPx = 0.5f) const;
};

/// What a frame's pixels say before the lens turns depth ranges into CoC ranges: each tile's
/// depth range, the |CoC| histogram, the highlight pixels and the luminance.
struct SceneMeasurement {
    cv::Size frame;      ///< the frame's size, pixels
    cv::Size tiles;      ///< tile grid (ceil(width / 16) x ceil(height / 16))
    cv::Mat tileMinDepth; ///< CV_32FC1 per tile, metres
    cv::Mat tileMaxDepth;
    std::array<int, SceneAnalysis::kHistogramEdges.size() + 1> histogram{}; ///< pixels per |CoC| bin
    std::size_t highlightPixels = 0; ///< 8-bit: any channel >= 250; float: luminance above 1
    cv::Mat tileHighlights;          ///< CV_32SC1 per tile: its highlight pixels
    cv::Mat tileLuminance;           ///< CV_32FC1 per tile: its pixels' linear Rec. 709 luminance summed
    std::size_t pixels = 0;
};

/// Measures a frame from its filled depth (CV_32FC1 metres) and colour (CV_8UC3 sRGB or CV_32FC3
/// linear, BGR), in bands of tile rows on OpenCV's threads: the pipeline's measurement on a
/// software renderer, where a compute pass per tile, which the plan waits for, took longer
/// (SceneMeasurePass: 34 against 1.3 ms at 640x480 on llvmpipe; docs/benchmarks.md, "Sprites on
/// their tiles, the analysis on the CPU").
SceneMeasurement measureScene(const cv::Mat& filledDepth, const cv::Mat& color, const CocCoefficients& k);

/// The analysis from a measurement: tile CoC ranges (CoC is monotonic in depth, so a tile's
/// range is the CoC of its depth range), frame range, foreground and its reach.
SceneAnalysis finishAnalysis(const SceneMeasurement& measurement, const CocCoefficients& k,
                             double invalidDepthFraction);

/// measureScene() then finishAnalysis(): the whole analysis on the CPU.
SceneAnalysis analyseScene(const cv::Mat& filledDepth, const cv::Mat& color, const CocCoefficients& k,
                           double invalidDepthFraction);

/// Which passes run, and on which tiles.
struct FramePlan {
    bool allInFocus = false;          ///< max |CoC| < 0.5 px: output = input, no pass runs
    std::vector<cv::Point> blurTiles; ///< tiles the blur passes process
    std::vector<cv::Point> copyTiles; ///< tiles only copied (in focus)
    bool holeFill = false;            ///< depth had holes to fill
    bool highlights = false;          ///< the frame has highlights (see highlightSprites, highlightGain)
    bool foreground = false;          ///< the frame has near blur
    bool nearField = false;           ///< the foreground layer passes run
    std::vector<cv::Point> nearTiles; ///< tiles the foreground layer covers
    HexagonKernel kernel = HexagonKernel::McIntoshMin; ///< the blur passes' kind, for explain()
    /// Resolution::Half: the tiles with pixels under 2 px of CoC, where the upscale puts the
    /// frame's own detail back (upscale.frag); on the others it only interpolates the blur.
    std::vector<cv::Point> detailTiles;
    Resolution resolution = Resolution::Full; ///< the blur passes' size, for explain()
    /// log2 of the frame's size over the blur passes': 0 full, 1 half, 2 quarter (Half with
    /// quarterOnLargeBlur on a frame whose blur is large).
    int blurShift = 0;
    /// Gain of the 8-bit highlight recovery in the CoC pass; 1 = not run (set by the pipeline).
    double highlightGain = 1.0;
    /// Rhombi: the light of blurred pixels above white goes to bokeh sprites (set by the pipeline
    /// for frames with highlights that can be that bright).
    bool highlightSprites = false;
    /// Rhombi: the blur loops unrolled to the tap count, because most blurred tiles have lines
    /// that long (rhombus_blur.frag UNROLLED); otherwise plain loops that stop at each line's end.
    bool unrolledTaps = false;
    /// The analysis' CoC (the gather's) over the lens': gatherScale() of the aperture, set by the
    /// pipeline; explain() reports the lens' CoC.
    float gatherScale = 1.0f;

    /// One line for --explain: the passes the composite runs (FrameGraph's names), then e.g. "blur on
    /// 812/1200 tiles (copy 388); ...; hole fill on (24.1 % invalid)".
    std::string explain(const SceneAnalysis& analysis) const;
};

/// `nearField`: spread foreground blur when the frame has some: McIntosh runs the foreground
/// layer on nearTiles; the rhombus blur reaches over them itself, so they join blurTiles.
/// `resolution` Half also sorts the tiles for the upscale (detailTiles). `taps` (rhombi): the
/// most taps per line, for unrolledTaps; 0 leaves the loops plain. `quarterOnLargeBlur` (Half
/// only): quarter size (blurShift 2) when more than kQuarterShare of the blurred pixels have
/// |CoC| >= kQuarterCocPx, the frame's large blur then spanning no more quarter-size pixels
/// than the 640x480 defaults' largest (32 px) spans half-size ones.
FramePlan makePlan(const SceneAnalysis& analysis, bool nearField = true,
                   HexagonKernel kernel = HexagonKernel::McIntoshMin, Resolution resolution = Resolution::Full,
                   int taps = 0, bool quarterOnLargeBlur = false);

/// The size makePlan() chooses for Half with quarterOnLargeBlur: 2 (quarter) or 1 (half).
int halfOrQuarterShift(const SceneAnalysis& analysis);

} // namespace defocus
