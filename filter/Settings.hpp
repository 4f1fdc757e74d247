// SPDX-License-Identifier: LGPL-2.1-or-later
// The filter's settings, one struct per concern, each field with its unit, default and range.
// All validation happens in validate() below: the CLI turns its messages into errors, an
// interactive session clamps with a warning.
#pragma once

#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "defocus/Settings.hpp" // limits: the ranges

namespace defocus {

/// How depth becomes a circle of confusion.
enum class CocModel {
    ThinLens,   ///< physical thin lens from focal length, f-number, focus distance, sensor width
    FocalRange  ///< blur rising linearly from the focus distance to max-coc at a near and a far limit
};

/// Where the image's field of view comes from, with the thin-lens model. The filter does not
/// reframe the picture; the two differ in how many of the image's pixels a blur on the sensor
/// spans, by the factor (S - f) / S at focus distance S: 0.983 at 85 mm focused at 5 m, 0.90 at
/// 0.85 m, the same at infinity.
enum class FieldOfView {
    /// A real camera: the sensor sits at the image distance v = f S / (S - f), so the field of
    /// view narrows as the lens focuses closer ("focus breathing").
    ImageDistance,
    /// Renderers (Blender Cycles, and engines with a physical camera): the field of view is
    /// 2 atan(sensor / 2f) whatever the focus, as if the sensor sat at the focal length.
    FocalLength
};

std::string_view fieldOfViewName(FieldOfView fov); ///< "image-distance", "focal-length"
/// Parses a name as printed by fieldOfViewName(); returns false when unknown.
bool parseFieldOfView(std::string_view name, FieldOfView& fov);

struct LensSettings {
    CocModel model = CocModel::ThinLens;
    /// Focal length, millimetres, [1, 1200].
    double focalLengthMm = 50.0;
    /// f-number N (aperture diameter = focal length / N), [0.7, 64].
    double fNumber = 2.0;
    /// Distance to the plane in focus, metres, (focal length, +inf]; +inf focuses at infinity.
    double focusM = 2.0;
    /// Sensor width, millimetres, [1, 100]; the image width is fitted to it.
    double sensorWidthMm = 36.0;
    /// Thin-lens model only: the distance behind the lens where the sensor width spans the image.
    FieldOfView fieldOfView = FieldOfView::ImageDistance;
    /// Largest CoC diameter, pixels, [0, 512]; larger blur is clamped to it.
    double maxCocPx = 32.0;
    /// Aperture blades: 0 = circular, else the regular polygon's corner count, [3, 16].
    int blades = 6;
    /// Rotation of the aperture, degrees counter-clockwise as seen in the image, [-180, 180], as
    /// Blender Cycles' blade rotation: at 0 an edge's normal points right, so the hexagon has a
    /// corner straight up (measured on data/blender_spheres; see docs/accuracy.md) and 30 (or 90)
    /// a flat edge on top, as in McIntosh et al.'s figures.
    double bladeRotationDeg = 0.0;
    /// Anamorphic squeeze, [0.1, 10]: the aperture's width is divided by it (Cycles' aperture
    /// ratio): 2 makes tall ovals.
    double apertureRatio = 1.0;
    /// FocalRange model only: distance where blur reaches max-coc in front of the focus, metres,
    /// [0, focusM).
    double nearLimitM = 1.0;
    /// FocalRange model only: distance where blur reaches max-coc behind the focus, metres,
    /// (focusM, +inf].
    double farLimitM = 6.0;
};

/// Render-target precision of the intermediate passes.
enum class TargetFormat {
    Rgba16F, ///< half float: enough for colour and a CoC in pixels, half the bandwidth
    Rgba32F, ///< full float
    /// The renderer's: RGBA16F on a GPU, whose passes it halves the bandwidth of, RGBA32F on a
    /// software renderer, which converts half floats on every fetch and store. The presets' (the
    /// corpus measured both within 0.02 dB on every scene: docs/benchmarks.md).
    Auto
};

/// The size the blur passes run at. The CoC pass, the scene analysis and the output are always
/// the frame's size.
enum class Resolution {
    Full, ///< every pass at the frame's size
    /// The CoC pass averages 2x2 pixels into a (w + 1) / 2 x (h + 1) / 2 target (CoC in pixels
    /// halves with the size), the blurs run there, and an upscale pass makes the frame-sized
    /// output: the blurred result interpolated, with the frame's own pixels put back where they
    /// are in focus (upscale.frag). About a quarter of the blur's cost. With
    /// QualitySettings::quarterOnLargeBlur, frames whose blur is large go to quarter size
    /// instead (FramePlan::blurShift).
    Half
};

std::string_view resolutionName(Resolution resolution); ///< "full", "half"
/// Parses a name as printed by resolutionName(); returns false when unknown.
bool parseResolution(std::string_view name, Resolution& resolution);

/// How the directional blurs make a hexagon.
enum class HexagonKernel {
    /// McIntosh, Riecke & DiPaola 2012: blur along an edge direction (the one nearest an axis:
    /// 0 deg for a flat top, as published), then +120 and -120 deg of that, and the per-channel
    /// min() of the two. Three passes and a composite; the min() keeps about 3/4 of a
    /// highlight's energy and darkens texture.
    McIntoshMin,
    /// Three one-sided rhombi summed (shaders/rhombus_blur.frag): a flat hexagon that keeps
    /// all of the energy, in two passes of two lines each, the composite fused into the second
    /// when the result is read. With nearField, foreground spreads by its own CoC ("scatter as
    /// gather").
    RhombiSum
};

std::string_view kernelName(HexagonKernel kernel); ///< "mcintosh", "rhombi"
/// Parses a name as printed by kernelName(); returns false when unknown.
bool parseKernel(std::string_view name, HexagonKernel& kernel);

/// The pipeline's defaults; the programs start from a preset instead (filter/Presets.hpp:
/// balanced = rhombi, 6 taps, near field, the renderer's precision).
struct QualitySettings {
    /// Taps per directional blur, [2, 64]: per centred segment (McIntosh), per one-sided line
    /// (rhombi; a line shorter than this many pixels takes one tap per pixel).
    int samples = 16;
    HexagonKernel kernel = HexagonKernel::RhombiSum;
    TargetFormat targetFormat = TargetFormat::Rgba16F;
    /// Size of the blur passes (see Resolution).
    Resolution resolution = Resolution::Full;
    /// Follow the per-frame plan: skip every pass when the frame is all in focus and blur only
    /// the tiles that need it. false runs every pass on every pixel (for comparisons).
    bool adaptive = true;
    /// Spread blurred foreground over what is behind it. McIntosh: a near-field layer,
    /// composited over the result. Rhombi: each line reaches as far as the foreground that can
    /// reach the pixel, and foreground taps count by their own CoC. Runs only on frames, and
    /// tiles, with foreground blur.
    bool nearField = false;
    /// Highlights from 8-bit input, [1, 64]: near-clipped pixels (any channel >= 0.96 linear)
    /// that get blurred are scaled up to this gain, so that lights in ordinary video bloom into
    /// bright hexagons. 1 = off (the default). Runs only on frames with clipped pixels; float
    /// input keeps its own HDR values.
    double highlightGain = 1.0;
    /// Rhombi: blurred pixels brighter than white (linear luminance 1: float input's HDR lights,
    /// 8-bit input's recovered ones) keep that much in the gather and scatter the rest as
    /// hexagons with exact edges (bokeh sprites), added to the result. Runs only on frames with
    /// such pixels.
    bool highlightSprites = true;
    /// Resolution::Half: the blurs run at quarter size on frames whose blur is large, as at
    /// 1920x1080 with max-coc scaled with the width: there a quarter-size pixel spans about
    /// as much of the CoC as a half-size one at 640x480 (makePlan() decides; FramePlan::blurShift),
    /// unless the frame has bokeh sprites (whose rims quarter size softens: the pipeline keeps
    /// those at half size). Off by default and in every preset: on the corpus enlarged 3x it
    /// cost 0.4 dB in the median (docs/benchmarks.md, "Quarter size on large blur").
    bool quarterOnLargeBlur = false;
};

/// What the pipeline writes out. The first five are the McIntosh lab's modes 1-5.
enum class View {
    Input,      ///< 1: the colour the blur starts from (after the CoC pass)
    Horizontal, ///< 2: after the first blur (McIntosh: along an edge; rhombi: X, the first line)
    DiagonalA,  ///< 3: that blurred at +120 degrees (rhombi: A, one rhombus)
    DiagonalB,  ///< 4: that blurred at -120 degrees (rhombi: B, two rhombi averaged)
    Composite,  ///< 5: the depth-of-field result (rhombi: (A + 2B) / 3; McIntosh: min(A, B))
    Depth,      ///< filled depth, colour-mapped, with a legend
    Coc         ///< signed CoC (near < 0 < far), colour-mapped, with a legend
};

inline constexpr View kAllViews[] = {View::Input,     View::Horizontal, View::DiagonalA, View::DiagonalB,
                                     View::Composite, View::Depth,      View::Coc};

std::string_view viewName(View view);
/// Parses a view name as printed by viewName(); returns false when unknown.
bool parseView(std::string_view name, View& view);

/// One problem with a setting: which parameter, its value, the allowed range.
struct SettingIssue {
    std::string parameter; ///< CLI name, e.g. "--f-number"
    std::string message;   ///< e.g. "--f-number must be between 0.7 and 64, not 0.5"
};

/// Checks every field against its documented range. With `clamp`, out-of-range values are
/// replaced by the nearest allowed one (the issues are still returned, as warnings).
std::vector<SettingIssue> validate(LensSettings& lens, bool clamp = false);
std::vector<SettingIssue> validate(QualitySettings& quality, bool clamp = false);

/// Parses a --focus value: metres, "inf"/"infinity" (focus at infinity) or "auto" (chosen from
/// the depth later; `lens.focusM` is left alone and `isAuto` set). Returns false for anything
/// else, leaving `lens` unchanged.
bool parseFocus(std::string_view text, LensSettings& lens, bool& isAuto);

/// The strict check of a command line: validate() of both structs, with an automatic focus
/// treated as valid (it is chosen, and checked, once the first depth is known).
std::vector<SettingIssue> validateCommandLine(const LensSettings& lens, QualitySettings quality, bool autoFocus);

} // namespace defocus
