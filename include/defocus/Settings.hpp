// SPDX-License-Identifier: LGPL-2.1-or-later
// The settings of defocus::Filter: the lens, how focus is chosen, the quality, what is written.
// Each field has its unit, range and default; names and ranges are the defocus command line's
// (`defocus --help`), so `--f-number 1.4` is `settings.lens.fNumber = 1.4`.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "defocus/Export.hpp"

namespace defocus {

/// The lens whose depth of field the filter gives the frames.
struct Lens {
    /// How depth becomes a blur diameter (circle of confusion, CoC). --coc-model
    enum class Model {
        ThinLens,  ///< "thin-lens": the physical lens of focal length, f-number and focus distance
        FocalRange ///< "focal-range": blur rises linearly from focusM to maxCocPx at nearM and farM
    };
    /// Where sensorWidthMm spans the image (thin lens only). --fov-from
    enum class FovFrom {
        ImageDistance, ///< "image-distance": a real camera, whose view narrows as it focuses closer
        FocalLength    ///< "focal-length": renderers (Blender Cycles, game engines)
    };

    /// Distance in focus, metres, (focal length, +inf]; +inf focuses at infinity. Default 2.
    /// Not used while AutofocusOptions::mode is on. --focus
    double focusM = 2.0;
    /// Aperture as an f-number N (aperture diameter = focal length / N), [0.7, 64]. Default 2.
    double fNumber = 2.0;
    /// Focal length, millimetres, [1, 1200]. Default 50.
    double focalLengthMm = 50.0;
    /// Sensor width the image width spans, millimetres, [1, 100]. Default 36 (full frame).
    double sensorWidthMm = 36.0;
    /// Default ImageDistance.
    FovFrom fovFrom = FovFrom::ImageDistance;
    /// Largest blur diameter, pixels, [0, 512]; larger blur is clamped. Default 32.
    double maxCocPx = 32.0;
    /// Default ThinLens.
    Model cocModel = Model::ThinLens;
    /// FocalRange only: metres where blur in front of the focus reaches maxCocPx, [0, focus). Default 1.
    double nearM = 1.0;
    /// FocalRange only: metres where blur behind the focus reaches maxCocPx, (focus, +inf]. Default 6.
    double farM = 6.0;
    /// Aperture blades: 0 for a circular aperture, else the regular polygon's corner count,
    /// [3, 16]. Default 6 (a hexagon). --blades
    int blades = 6;
    /// Aperture rotation, degrees counter-clockwise, [-180, 180], as Blender Cycles' blade
    /// rotation: at 0 one edge faces right, so a hexagon has a corner on top (30 = a flat top)
    /// and a pentagon a corner pointing left. Default 0. --blade-rotation
    double bladeRotationDeg = 0.0;
    /// Anamorphic squeeze, (Cycles' aperture ratio), [0.1, 10]: the aperture's width is divided
    /// by it, so 2 gives tall ovals, 0.5 wide ones. Default 1. --aperture-ratio
    double apertureRatio = 1.0;
};

/// How the focus distance is chosen.
struct AutofocusOptions {
    enum class Mode {
        /// Lens::focusM as given.
        Off,
        /// The command line's `--focus auto`: the median valid depth of the central 10 % (of
        /// each axis) of the first frame after construction or reset(), then fixed.
        FirstFrame,
        /// The live preview's autofocus: the weighted mean of 1/depth over the central 10 %,
        /// followed smoothly by a critically damped spring in dioptres (a step reaches 95 % of
        /// its way in 4.7 time constants), with a dead band of 0.02 dioptres against sensor noise.
        Follow
    };
    /// Default Off.
    Mode mode = Mode::Off;
    /// Follow: the spring's time constant, seconds, >= 0 and finite; 0 jumps at once. Default 0.25.
    double timeConstantS = 0.25;
};

/// Speed against accuracy. A preset sets every field left empty; a field that is set overrides
/// it, as the command line's flags override --quality.
struct Quality {
    /// --quality: from the accuracy benchmark (docs/accuracy.md); all use the rhombus kernel
    /// with its near field and 32-bit float targets.
    enum class Preset {
        Fast,     ///< "fast": 4 taps per line, blurs at half size
        Balanced, ///< "balanced": 6 taps, half size
        High      ///< "high": 12 taps, full size
    };
    /// --hexagon: how the directional blurs make the hexagon.
    enum class Hexagon {
        Rhombi,  ///< "rhombi": three one-sided rhombi summed; keeps a highlight's energy
        McIntosh ///< "mcintosh": McIntosh et al. 2012, the min() of two rhombi
    };
    /// --precision of the intermediate render targets.
    enum class Precision { F16, F32 };
    /// --resolution the blurs run at; the output always has the frame's size.
    enum class Resolution { Full, Half };

    /// Default Balanced.
    Preset preset = Preset::Balanced;
    /// Taps per directional blur, [2, 64]. Default: the preset's.
    std::optional<int> samples;
    /// Default: the preset's (Rhombi).
    std::optional<Hexagon> hexagon;
    /// Default: the preset's, the renderer's own: F16 on a GPU, F32 on a software renderer
    /// (llvmpipe), where half floats are converted on every fetch and store.
    std::optional<Precision> precision;
    /// Default: the preset's.
    std::optional<Resolution> resolution;
    /// Spread blurred foreground over what is behind it. Default: the preset's (on).
    std::optional<bool> nearField;
    /// Rhombi: lights brighter than white scatter as hexagons with exact edges. Default on.
    bool highlightSprites = true;
    /// 8-bit input: near-clipped pixels that get blurred are scaled up to this, so lights bloom,
    /// [1, 64]; 1 = off. Default 1.
    double highlightGain = 1.0;
    /// Run every pass on every pixel, ignoring the per-frame plan (for comparisons). Default off.
    bool alwaysOn = false;
};

struct Settings {
    /// --view: what the filter returns; the first five are the stages of the blur.
    enum class View { Input, Horizontal, DiagonalA, DiagonalB, Composite, Depth, Coc };
    /// How the result is returned.
    enum class Output {
        Srgb8,     ///< CV_8UC3 BGR, sRGB-encoded (what an 8-bit image or video holds)
        Linear32F, ///< CV_32FC3 BGR, scene-linear, unclipped (HDR kept)
        Srgb8Bgra  ///< CV_8UC4 BGRA, sRGB-encoded, alpha 255 (GStreamer's BGRx and BGRA, no conversion)
    };

    Lens lens;
    AutofocusOptions autofocus;
    Quality quality;
    /// Default Composite (the result).
    View view = View::Composite;
    /// Default Srgb8.
    Output output = Output::Srgb8;
    /// Units per metre of 16-bit depth images, > 0. Default 1000 (millimetres, most sensors);
    /// TUM RGB-D uses 5000.
    double depthScale = 1000.0;
};

/// Every view, in --view's order (the preview's keys 1 to 7).
inline constexpr Settings::View kViews[] = {Settings::View::Input,     Settings::View::Horizontal,
                                            Settings::View::DiagonalA, Settings::View::DiagonalB,
                                            Settings::View::Composite, Settings::View::Depth,
                                            Settings::View::Coc};
/// --view's word for `view`: "input", "horizontal", "diagonal-a", "diagonal-b", "composite",
/// "depth" or "coc".
DEFOCUS_API std::string_view viewName(Settings::View view);
/// The view --view calls `name`; nullopt for any other word.
DEFOCUS_API std::optional<Settings::View> viewNamed(std::string_view name);
/// --quality's word for `preset`: "fast", "balanced" or "high".
DEFOCUS_API std::string_view qualityName(Quality::Preset preset);
/// The preset --quality calls `name`; nullopt for any other word.
DEFOCUS_API std::optional<Quality::Preset> qualityNamed(std::string_view name);

/// The range of each setting, {lowest, highest} allowed, as the command line's options, check()
/// and the GStreamer element's properties take them.
namespace limits {
inline constexpr double kFocalLengthMm[] = {1.0, 1200.0};
inline constexpr double kFNumber[] = {0.7, 64.0};
inline constexpr double kSensorWidthMm[] = {1.0, 100.0};
inline constexpr double kMaxCocPx[] = {0.0, 512.0};
inline constexpr double kBladeRotationDeg[] = {-180.0, 180.0};
/// Lens::blades: 0 (circular) or this range.
inline constexpr int kBlades[] = {3, 16};
inline constexpr double kApertureRatio[] = {0.1, 10.0};
inline constexpr int kSamples[] = {2, 64};
inline constexpr double kHighlightGain[] = {1.0, 64.0};
/// Lens::focusM: +inf included; check() also holds it beyond the focal length.
inline constexpr double kFocusM[] = {kFocalLengthMm[0] * 1e-3, std::numeric_limits<double>::infinity()};
/// Lens::nearM and Lens::farM: +inf included; check() also holds them either side of the focus.
inline constexpr double kNearFarM[] = {0.0, std::numeric_limits<double>::infinity()};
/// AutofocusOptions::timeConstantS: any finite time.
inline constexpr double kTimeConstantS[] = {0.0, std::numeric_limits<double>::max()};
/// Settings::depthScale: any positive finite number of units per metre.
inline constexpr double kDepthScale[] = {std::numeric_limits<double>::min(), std::numeric_limits<double>::max()};
} // namespace limits

/// Checks every field against its range, with the command line's words: each problem is one
/// message such as "--f-number must be between 0.7 and 64, not 0.5"; none means valid. With `clamp`, each
/// value out of range is replaced by the nearest allowed one (the messages say what was wrong).
DEFOCUS_API std::vector<std::string> check(Settings& settings, bool clamp = false);

/// `quality` with every field left empty set to its preset's value (what the filter runs), but
/// `precision`, which stays empty where the preset leaves it to the renderer.
DEFOCUS_API Quality resolve(const Quality& quality);

/// The library's version, "MAJOR.MINOR.PATCH".
DEFOCUS_API std::string version();

} // namespace defocus
