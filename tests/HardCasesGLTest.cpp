// SPDX-License-Identifier: LGPL-2.1-or-later
// The hard-case suite: broken depth, extreme lens and quality settings, degenerate image sizes
// and hostile colour, each run through both kernels (the rhombi and McIntosh's chain, with the
// pipeline's plain settings) and the shipped presets (high at full size; balanced and fast, at
// half size, by their own bounds). Every intermediate target and both output encodings must be
// finite, inside the input's colour range, unchanged where in focus, and move by a bounded
// amount when a lens parameter changes by 1 %.
#include <map>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "filter/Aperture.hpp"
#include "filter/ColorSpace.hpp"
#include "filter/DepthPrep.hpp"
#include "filter/Lens.hpp"
#include "filter/Pipeline.hpp"
#include "filter/SceneAnalysis.hpp"
#include "filter/passes/HighlightSpritePass.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kFloatMax = std::numeric_limits<float>::max();

/// What coc.frag clamps colour to (CocPass.cpp: the half-float maximum, or for full float what
/// hex_blur.frag can sum over 64 taps without overflowing).
float largestColor(TargetFormat format)
{
    return format == TargetFormat::Rgba16F ? 65504.0f : kFloatMax / 64.0f;
}

/// Relative tolerance of a colour that went through the targets. One rounding to half float moves
/// a value by at most 2^-11 of itself (11-bit significand); the weighted average in hex_blur.frag
/// adds float32 rounding (2^-24 per operation, a few dozen operations). 2^-10 covers both with a
/// factor two to spare. Full-float targets only see the float32 rounding: 2^-16 is generous.
double relativeTolerance(TargetFormat format)
{
    return format == TargetFormat::Rgba16F ? 0x1p-10 : 0x1p-16;
}
/// Absolute floor for values near 0: half-float subnormals are spaced 2^-24.
constexpr double kAbsoluteTolerance = 0x1p-24;

/// How far the GPU's decode of the 8-bit sRGB value `byte` may sit from the exact one: half the
/// linear step to the next value, i.e. anything that still encodes back to `byte`. llvmpipe
/// decodes sRGB8 textures with an approximation; measured on the ColorEvery8BitValueInFocus case:
/// up to 2.5 % relative near black, 0.35 of a step at worst.
double decodeTolerance(int byte)
{
    const int low = std::min(byte, 254);
    return 0.5 * (srgbToLinear(static_cast<float>(low + 1) / 255.0f) - srgbToLinear(static_cast<float>(low) / 255.0f));
}

/// Slack of a linear value `value` that came from `byte` (-1 for float input) through `format` targets.
double slack(double value, int byte, TargetFormat format)
{
    return relativeTolerance(format) * std::abs(value) + kAbsoluteTolerance + (byte >= 0 ? decodeTolerance(byte) : 0.0);
}

// ---------------------------------------------------------------------------------------------
// Inputs

enum class ColorKind {
    Pattern8,      ///< checkerboard + gradients + noise, 8-bit sRGB
    PatternFloat,  ///< the same pattern, scene-linear float
    Ramp8,         ///< every 8-bit value, one per column, in all three channels
    Zero8,         ///< constant 0, 8-bit
    OneFloat,      ///< constant 1.0, float
    Hdr1e4,        ///< float pattern with 1e4 highlights every 8 px
    HdrBeyondHalf, ///< float pattern times 1e5: partly above what a half float holds
    NaNFloat,      ///< float pattern with NaN pixels (one or all channels)
    InfFloat,      ///< float pattern with +Inf and -Inf pixels
    NegativeFloat, ///< float pattern shifted to [-0.5, 0.5]
    FloatMax,      ///< float pattern with FLT_MAX highlights
    Bleeding       ///< float pattern with magenta pixels where DepthKind::Bleeding is far
};

enum class DepthKind {
    Scene,     ///< far ramp (6 m top .. 1.2 m bottom), a near box (0.7 m), a box on the focus (2 m)
    Holes,     ///< Scene with scattered pixels and a block set to `depthValue`
    Step,      ///< 0.3 m left half, 100 m right half
    Invalid,   ///< every pixel a different kind of invalid (0, <0, NaN, +-Inf, denormal)
    None,      ///< no depth map at all
    HalfSize,  ///< Scene at half the colour size (resized by nearest neighbour)
    Bleeding   ///< 1 m everywhere, isolated pixels at 3 m on an 8 px grid
};

/// What the case must show about the blur, so that each case really exercises what it names.
enum class Blur {
    Any,  ///< no expectation
    Some, ///< at least one pixel has |CoC| >= 0.5 px
    None  ///< every pixel is in focus
};

struct HardCase {
    const char* name;
    cv::Size size{64, 48};
    ColorKind color = ColorKind::Pattern8;
    DepthKind depth = DepthKind::Scene;
    float depthValue = 0.0f;
    /// Changes to the base settings (85 mm f/1.4 focused at 2 m, 36 mm sensor, max-coc 32 px).
    void (*setup)(LensSettings&, QualitySettings&) = nullptr;
    /// validate() must refuse the settings, naming this parameter (e.g. "--focus"); they are then
    /// rendered as validate(clamp = true) leaves them.
    const char* rejects = nullptr;
    Blur blur = Blur::Any;
    /// The composite must equal the Input target everywhere (blurry pixels included).
    bool unchanged = false;
    /// Re-render with each lens parameter changed by 1 % (off at 4K: seconds per render).
    bool continuity = true;
    /// Also render with RGBA32F targets and bound the difference (half-float precision).
    bool compareWith32F = false;
};

void PrintTo(const HardCase& c, std::ostream* os)
{
    *os << c.name;
}

LensSettings baseLens()
{
    LensSettings lens;
    lens.focalLengthMm = 85.0;
    lens.fNumber = 1.4;
    lens.focusM = 2.0;
    lens.sensorWidthMm = 36.0;
    lens.maxCocPx = 32.0;
    return lens;
}

/// Scene-linear colour in [0.01, 0.99]: a 6 px checkerboard (hard edges), gradients and noise.
cv::Mat linearPattern(cv::Size size)
{
    cv::Mat out(size, CV_32FC3);
    cv::RNG rng(1234);
    rng.fill(out, cv::RNG::UNIFORM, -0.05, 0.05);
    for (int y = 0; y < size.height; ++y) {
        auto* row = out.ptr<cv::Vec3f>(y);
        const float v = (static_cast<float>(y) + 0.5f) / static_cast<float>(size.height);
        for (int x = 0; x < size.width; ++x) {
            const float u = (static_cast<float>(x) + 0.5f) / static_cast<float>(size.width);
            const float check = ((x / 6 + y / 6) % 2) != 0 ? 0.75f : 0.2f;
            const cv::Vec3f c = row[x] + cv::Vec3f(check + 0.15f * u, 1.0f - check + 0.1f * v, 0.3f + 0.4f * u * v);
            for (int i = 0; i < 3; ++i)
                row[x][i] = std::clamp(c[i], 0.01f, 0.99f);
        }
    }
    return out;
}

/// True on the 8 px grid of isolated far pixels of DepthKind::Bleeding.
bool bleedingCentre(int x, int y)
{
    return x % 8 == 4 && y % 8 == 4;
}

cv::Mat makeColor(ColorKind kind, cv::Size size)
{
    cv::Mat linear = linearPattern(size);
    switch (kind) {
    case ColorKind::Pattern8: return encodeSrgb(linear);
    case ColorKind::PatternFloat: return linear;
    case ColorKind::Ramp8: {
        cv::Mat ramp(size, CV_8UC3);
        ramp.forEach<cv::Vec3b>([](cv::Vec3b& c, const int* at) { c = cv::Vec3b::all(static_cast<uchar>(at[1] % 256)); });
        return ramp;
    }
    case ColorKind::Zero8: return cv::Mat(size, CV_8UC3, cv::Scalar::all(0));
    case ColorKind::OneFloat: return cv::Mat(size, CV_32FC3, cv::Scalar::all(1.0));
    case ColorKind::NegativeFloat: return linear - cv::Scalar::all(0.5);
    case ColorKind::HdrBeyondHalf: return linear * 1e5;
    default: break;
    }
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            cv::Vec3f& c = linear.at<cv::Vec3f>(y, x);
            const bool spot = x % 8 == 3 && y % 8 == 5;
            if (kind == ColorKind::Hdr1e4 && spot)
                c = cv::Vec3f::all(1e4f);
            else if (kind == ColorKind::FloatMax && spot)
                c = cv::Vec3f(kFloatMax, 1.0f, kFloatMax);
            else if (kind == ColorKind::NaNFloat && spot)
                c = (x / 8) % 2 != 0 ? cv::Vec3f::all(kNaN) : cv::Vec3f(0.5f, kNaN, 0.5f);
            else if (kind == ColorKind::InfFloat && spot)
                c = (x / 8) % 2 != 0 ? cv::Vec3f(kInf, 0.5f, -kInf) : cv::Vec3f::all(-kInf);
            else if (kind == ColorKind::Bleeding && bleedingCentre(x, y))
                c = cv::Vec3f(0.95f, 0.05f, 0.95f);
        }
    return linear;
}

cv::Mat sceneDepth(cv::Size size)
{
    cv::Mat depth(size, CV_32F);
    const int w = size.width, h = size.height;
    for (int y = 0; y < h; ++y) {
        auto* row = depth.ptr<float>(y);
        const float ramp = 6.0f * std::pow(1.2f / 6.0f, (static_cast<float>(y) + 0.5f) / static_cast<float>(h));
        const bool boxRows = y >= h / 4 && y < 3 * h / 4;
        for (int x = 0; x < w; ++x) {
            row[x] = ramp;
            if (boxRows && x >= w / 8 && x < 3 * w / 8)
                row[x] = 0.7f;
            if (boxRows && x >= 5 * w / 8 && x < 7 * w / 8)
                row[x] = 2.0f;
        }
    }
    return depth;
}

cv::Mat makeDepth(DepthKind kind, float value, cv::Size size)
{
    switch (kind) {
    case DepthKind::Scene: return sceneDepth(size);
    case DepthKind::None: return {};
    case DepthKind::HalfSize: return sceneDepth({std::max(1, size.width / 2), std::max(1, size.height / 2)});
    default: break;
    }
    cv::Mat depth = kind == DepthKind::Holes ? sceneDepth(size) : cv::Mat(size, CV_32F, cv::Scalar(1.0f));
    const float invalid[] = {0.0f, -1.0f, kNaN, kInf, -kInf, 1e-40f};
    const int w = size.width, h = size.height;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float& z = depth.at<float>(y, x);
            switch (kind) {
            case DepthKind::Holes:
                if ((x * 7 + y * 13) % 11 == 0 || (std::abs(x - w / 2) < 5 && std::abs(y - h / 2) < 4))
                    z = value;
                break;
            case DepthKind::Step: z = x < w / 2 ? 0.3f : 100.0f; break;
            case DepthKind::Invalid: z = invalid[(x + 2 * y) % 6]; break;
            case DepthKind::Bleeding: z = bleedingCentre(x, y) ? 3.0f : 1.0f; break;
            default: break;
            }
        }
    return depth;
}

// ---------------------------------------------------------------------------------------------
// The cases

void focalRange(LensSettings& lens)
{
    lens.model = CocModel::FocalRange;
    lens.focusM = 2.0;
    lens.nearLimitM = 1.0;
    lens.farLimitM = 6.0;
}

const HardCase kCases[] = {
    // Depth: every kind of missing measurement is filled, none reaches the shaders.
    {.name = "DepthZero", .depth = DepthKind::Holes, .depthValue = 0.0f, .blur = Blur::Some},
    {.name = "DepthNaN", .depth = DepthKind::Holes, .depthValue = kNaN, .blur = Blur::Some},
    {.name = "DepthPlusInf", .depth = DepthKind::Holes, .depthValue = kInf, .blur = Blur::Some},
    {.name = "DepthMinusInf", .depth = DepthKind::Holes, .depthValue = -kInf, .blur = Blur::Some},
    {.name = "DepthNegative", .depth = DepthKind::Holes, .depthValue = -2.0f, .blur = Blur::Some},
    {.name = "DepthDenormal", .depth = DepthKind::Holes, .depthValue = 1e-40f, .blur = Blur::Some},
    {.name = "DepthJustAboveMinimum", .depth = DepthKind::Holes, .depthValue = 1.01e-4f, .blur = Blur::Some},
    {.name = "DepthOutlier65m", .depth = DepthKind::Holes, .depthValue = 65.535f, .blur = Blur::Some},
    {.name = "DepthFloatMax", .depth = DepthKind::Holes, .depthValue = kFloatMax, .blur = Blur::Some},
    {.name = "DepthStep0p3To100",
     .depth = DepthKind::Step,
     .setup = [](LensSettings& l, QualitySettings&) { l.focusM = 0.3; },
     .blur = Blur::Some},
    {.name = "DepthAllInvalid", .depth = DepthKind::Invalid, .blur = Blur::None},
    {.name = "DepthMissing", .depth = DepthKind::None, .blur = Blur::None},
    {.name = "DepthHalfResolution", .depth = DepthKind::HalfSize, .blur = Blur::Some},

    // Focus distance.
    {.name = "FocusEqualsFocalLength",
     .setup = [](LensSettings& l, QualitySettings&) { l.focusM = l.focalLengthMm * 1e-3; },
     .rejects = "--focus",
     .blur = Blur::Some},
    {.name = "FocusBelowFocalLength",
     .setup = [](LensSettings& l, QualitySettings&) { l.focusM = 0.01; },
     .rejects = "--focus",
     .blur = Blur::Some},
    {.name = "FocusJustBeyondFocalLength",
     .setup = [](LensSettings& l, QualitySettings&) { l.focusM = std::nextafter(l.focalLengthMm * 1e-3, 1.0); },
     .blur = Blur::Some},
    {.name = "FocusAtInfinity",
     .setup = [](LensSettings& l, QualitySettings&) { l.focusM = std::numeric_limits<double>::infinity(); },
     .blur = Blur::Some},
    {.name = "FocusNaN",
     .setup = [](LensSettings& l, QualitySettings&) { l.focusM = std::nan(""); },
     .rejects = "--focus",
     .blur = Blur::Some},

    // Every lens parameter at its documented minimum and maximum.
    {.name = "FNumber0p7", .setup = [](LensSettings& l, QualitySettings&) { l.fNumber = 0.7; }, .blur = Blur::Some},
    {.name = "FNumber64", .setup = [](LensSettings& l, QualitySettings&) { l.fNumber = 64.0; }},
    {.name = "FocalLength1mm", .setup = [](LensSettings& l, QualitySettings&) { l.focalLengthMm = 1.0; }},
    {.name = "FocalLength1200mm",
     .setup = [](LensSettings& l, QualitySettings&) { l.focalLengthMm = 1200.0; },
     .blur = Blur::Some},
    {.name = "SensorWidth1mm",
     .setup = [](LensSettings& l, QualitySettings&) { l.sensorWidthMm = 1.0; },
     .blur = Blur::Some},
    {.name = "SensorWidth100mm",
     .setup = [](LensSettings& l, QualitySettings&) { l.sensorWidthMm = 100.0; },
     .blur = Blur::Some},
    {.name = "MaxCoc0", .setup = [](LensSettings& l, QualitySettings&) { l.maxCocPx = 0.0; }, .blur = Blur::None},
    {.name = "MaxCoc512",
     .setup = [](LensSettings& l, QualitySettings&) { l.maxCocPx = 512.0; },
     .blur = Blur::Some},
    {.name = "LensAllNaN",
     .setup =
         [](LensSettings& l, QualitySettings& q) {
             l.focalLengthMm = l.fNumber = l.focusM = l.sensorWidthMm = l.maxCocPx = std::nan("");
             q.samples = -7;
         },
     .rejects = "--samples"},
    {.name = "FocalRangeNearLimit0",
     .setup =
         [](LensSettings& l, QualitySettings&) {
             focalRange(l);
             l.nearLimitM = 0.0;
         },
     .blur = Blur::Some},
    {.name = "FocalRangeNearLimitJustBeforeFocus",
     .setup =
         [](LensSettings& l, QualitySettings&) {
             focalRange(l);
             l.nearLimitM = std::nextafter(2.0, 0.0);
         },
     .blur = Blur::Some},
    {.name = "FocalRangeFarLimitJustBeyondFocus",
     .setup =
         [](LensSettings& l, QualitySettings&) {
             focalRange(l);
             l.farLimitM = std::nextafter(2.0, 3.0);
         },
     .blur = Blur::Some},
    {.name = "FocalRangeFarLimitInfinity",
     .setup =
         [](LensSettings& l, QualitySettings&) {
             focalRange(l);
             l.farLimitM = std::numeric_limits<double>::infinity();
         },
     .blur = Blur::Some},
    {.name = "FocalRangeFocusAtInfinity",
     .setup =
         [](LensSettings& l, QualitySettings&) {
             focalRange(l);
             l.focusM = l.farLimitM = std::numeric_limits<double>::infinity();
         },
     .blur = Blur::Some},

    // Quality settings at their limits.
    {.name = "Samples2", .setup = [](LensSettings&, QualitySettings& q) { q.samples = 2; }, .blur = Blur::Some},
    {.name = "Samples64", .setup = [](LensSettings&, QualitySettings& q) { q.samples = 64; }, .blur = Blur::Some},
    {.name = "TargetsRgba32F",
     .setup = [](LensSettings&, QualitySettings& q) { q.targetFormat = TargetFormat::Rgba32F; },
     .blur = Blur::Some},

    // CoC extremes.
    {.name = "MaxCocLargerThanImage",
     .setup =
         [](LensSettings& l, QualitySettings&) {
             l.fNumber = 0.7;
             l.focusM = 0.2;
             l.maxCocPx = 512.0;
         },
     .blur = Blur::Some},
    {.name = "CocBelowHalfPixelEverywhere",
     .setup = [](LensSettings& l, QualitySettings&) { l.maxCocPx = 0.49; },
     .blur = Blur::None},

    // Image sizes (width x height).
    {.name = "Image1x1", .size = {1, 1}},
    {.name = "Image1xN", .size = {1, 48}},
    {.name = "ImageNx1", .size = {64, 1}},
    {.name = "Image7x5", .size = {7, 5}},
    {.name = "Image641x479", .size = {641, 479}, .blur = Blur::Some},
    {.name = "Image3840x2160", .size = {3840, 2160}, .blur = Blur::Some, .continuity = false},

    // Colour.
    {.name = "ColorEvery8BitValueInFocus", .size = {256, 2}, .color = ColorKind::Ramp8, .depth = DepthKind::None,
     .blur = Blur::None},
    {.name = "ColorAllZero", .color = ColorKind::Zero8, .blur = Blur::Some},
    // Every average of 1 is 1, whatever the kernel, the near field or the bleeding rule do: the
    // composite is the input everywhere. With the near field (high preset) the in-focus box lies
    // within the near box's reach but beyond its cover, where rhombus_blur.frag's lines keep no
    // weight and must fall back to the centre (a defect there turns the box black).
    {.name = "ColorAllOne", .color = ColorKind::OneFloat, .blur = Blur::Some, .unchanged = true},
    {.name = "HdrColor1e4", .color = ColorKind::Hdr1e4, .blur = Blur::Some},
    {.name = "HdrColorBeyondHalfFloat", .color = ColorKind::HdrBeyondHalf, .blur = Blur::Some},
    {.name = "ColorNaNInFloatInput", .color = ColorKind::NaNFloat, .blur = Blur::Some},
    {.name = "ColorNaNInFloatInputAllInFocus", .color = ColorKind::NaNFloat, .depth = DepthKind::None,
     .blur = Blur::None},
    {.name = "ColorInfInFloatInput", .color = ColorKind::InfFloat, .blur = Blur::Some},
    {.name = "ColorNegativeInFloatInput", .color = ColorKind::NegativeFloat, .blur = Blur::Some},
    {.name = "ColorFloatMaxInRgba32F",
     .color = ColorKind::FloatMax,
     .setup = [](LensSettings&, QualitySettings& q) { q.targetFormat = TargetFormat::Rgba32F; },
     .blur = Blur::Some},

    // The bleeding rule rejects every tap: far pixels (CoC 4 px) ringed by pixels exactly on the
    // focus plane (CoC exactly 0: focal range with focus 1 m gives c = s * 1 - s). McIntosh:
    // with two taps at +-2 px, each tap's bilinear footprint holds only in-focus texels, so each
    // is nearer than the centre with blurriness 0: weight 0 * bleedingMult = 0, total weight 0,
    // and hex_blur.frag's centre must fill the missing weight (a defect there, dividing the
    // empty sum, turns these pixels black). The rhombi: every tap of every line is rejected and
    // the centre's own share of its line is all that is left. Their other fallback, a line with
    // no weight at all (an in-focus pixel that the near field's lines reach, but no foreground
    // covers), is held by ColorAllOne on the high preset.
    {.name = "EveryNeighbourRejectedByBleedingRule",
     .color = ColorKind::Bleeding,
     .depth = DepthKind::Bleeding,
     .setup =
         [](LensSettings& l, QualitySettings& q) {
             l.model = CocModel::FocalRange;
             l.focusM = 1.0;
             l.nearLimitM = 0.5;
             l.farLimitM = 2.0;
             l.maxCocPx = 4.0;
             q.samples = 2;
         },
     .blur = Blur::Some,
     .unchanged = true},

    // Half-float targets at 4K with a 64 px CoC: positions and weights must not degrade.
    {.name = "Half16FCoc64At4K",
     .size = {3840, 2160},
     .setup = [](LensSettings& l, QualitySettings&) { l.maxCocPx = 64.0; },
     .blur = Blur::Some,
     .continuity = false,
     .compareWith32F = true},
};

// ---------------------------------------------------------------------------------------------
// Checks

cv::Mat channel(const cv::Mat& image, int index)
{
    cv::Mat out;
    cv::extractChannel(image, out, index);
    return out;
}

/// What the output may be compared with. A colour can leave the pipeline two ways: through the
/// GPU passes, which sanitise it as coc.frag does (NaN -> 0, then clamped to [0, largest], so
/// +Inf becomes largest), or, for a frame with nothing to blur, through the same clean-up on the
/// CPU (sanitizeLinear). Either is "unchanged".
struct Reference {
    cv::Mat sanitised, raw;           ///< CV_32FC3 linear; raw has +inf where the input is not finite
    cv::Mat sanitisedSlack, rawSlack; ///< CV_32FC3, how far an unchanged value may sit from each
    cv::Mat srgb, srgbRaw;            ///< CV_8UC3 encodes of the two (the input itself if 8-bit)
    /// Per-channel range over the finite input and its sanitised form, and the slack around it.
    cv::Vec3d lo, hi, loSlack, hiSlack;
    cv::Vec3d lo8, hi8; ///< per-channel range of both encodes
    /// Largest hi - lo over the channels; for a constant input its largest value (changes then
    /// read as relative ones), 1 for black. Continuity is measured in shares of it.
    double span = 0.0;
};

Reference makeReference(const cv::Mat& color, TargetFormat format)
{
    Reference r;
    const bool bytes = color.depth() == CV_8U;
    const float largest = largestColor(format);
    r.raw = bytes ? decodeSrgb(color) : color.clone();
    r.sanitised = sanitizeLinear(r.raw, largest);
    r.srgb = bytes ? color : encodeSrgb(r.sanitised);
    r.srgbRaw = bytes ? color : encodeSrgb(r.raw);
    // Range over both references (non-finite input values left out).
    r.lo = cv::Vec3d::all(std::numeric_limits<double>::infinity());
    r.hi = -r.lo;
    for (const cv::Mat* m : {&r.raw, &r.sanitised})
        for (int y = 0; y < m->rows; ++y)
            for (int x = 0; x < m->cols; ++x)
                for (int i = 0; i < 3; ++i)
                    if (const float v = m->at<cv::Vec3f>(y, x)[i]; std::isfinite(v)) {
                        r.lo[i] = std::min(r.lo[i], static_cast<double>(v));
                        r.hi[i] = std::max(r.hi[i], static_cast<double>(v));
                    }
    r.raw.forEach<cv::Vec3f>([](cv::Vec3f& c, const int*) {
        for (int i = 0; i < 3; ++i)
            c[i] = std::isfinite(c[i]) ? c[i] : std::numeric_limits<float>::infinity();
    });
    // slack() for every value at once: relative + absolute, plus the decode tolerance of its byte.
    r.sanitisedSlack = cv::abs(r.sanitised) * relativeTolerance(format) + cv::Scalar::all(kAbsoluteTolerance);
    if (bytes) {
        cv::Mat table(1, 256, CV_32F), decode;
        for (int byte = 0; byte < 256; ++byte)
            table.at<float>(byte) = static_cast<float>(decodeTolerance(byte));
        cv::LUT(color, table, decode);
        r.sanitisedSlack += decode;
    }
    r.rawSlack = bytes ? r.sanitisedSlack : cv::abs(r.raw) * relativeTolerance(format) + cv::Scalar::all(kAbsoluteTolerance);
    double magnitude = 0.0;
    for (int i = 0; i < 3; ++i) {
        double lo8 = 0, hi8 = 0, loRaw8 = 0, hiRaw8 = 0;
        cv::minMaxLoc(channel(r.srgb, i), &lo8, &hi8);
        cv::minMaxLoc(channel(r.srgbRaw, i), &loRaw8, &hiRaw8);
        r.lo8[i] = std::min(lo8, loRaw8);
        r.hi8[i] = std::max(hi8, hiRaw8);
        r.loSlack[i] = slack(r.lo[i], bytes ? static_cast<int>(r.lo8[i]) : -1, format);
        r.hiSlack[i] = slack(r.hi[i], bytes ? static_cast<int>(r.hi8[i]) : -1, format);
        r.span = std::max(r.span, r.hi[i] - r.lo[i]);
        magnitude = std::max({magnitude, std::abs(r.lo[i]), std::abs(r.hi[i])});
    }
    if (r.span == 0.0)
        r.span = magnitude > 0.0 ? magnitude : 1.0;
    return r;
}

/// Counts the pixels of `image` (3 channels, float or 8-bit) with a channel outside
/// [lo - loSlack, hi + hiSlack]; describes the first one in `first`.
int countOutOfRange(const cv::Mat& image, const cv::Vec3d& lo, const cv::Vec3d& hi, const cv::Vec3d& loSlack,
                    const cv::Vec3d& hiSlack, std::string& first)
{
    cv::Mat inside;
    cv::inRange(image, cv::Scalar(lo - loSlack), cv::Scalar(hi + hiSlack), inside);
    const int count = static_cast<int>(image.total()) - cv::countNonZero(inside);
    if (count > 0) {
        cv::Point at;
        cv::minMaxLoc(inside, nullptr, nullptr, &at);
        cv::Vec3d value;
        image.row(at.y).col(at.x).convertTo(cv::Mat(1, 1, CV_64FC3, &value), CV_64F);
        first = cv::format("(%d, %d) = (%g, %g, %g) outside [(%g, %g, %g), (%g, %g, %g)]", at.x, at.y, value[0],
                           value[1], value[2], lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    }
    return count;
}

/// Pixels (CV_8U mask) where any channel of the 3-channel `a` and `b` differ by more than the
/// matching value of `limit`.
cv::Mat differsBeyond(const cv::Mat& a, const cv::Mat& b, const cv::Mat& limit)
{
    cv::Mat diff, any;
    cv::absdiff(a, b, diff);
    const cv::Mat beyond = diff > limit;
    cv::reduce(beyond.reshape(1, static_cast<int>(beyond.total())), any, 1, cv::REDUCE_MAX);
    return any.reshape(1, a.rows);
}

/// Largest absolute difference of two 3-channel float images inside `mask` (everywhere if empty).
double maxRgbDifference(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask)
{
    return cv::norm(a, b, cv::NORM_INF, mask);
}

struct Change {
    double mean = 0.0; ///< mean absolute change over pixels and channels, as a share of the span
    double max = 0.0;  ///< largest absolute change, as a share of the span
};

Change relativeChange(const cv::Mat& a, const cv::Mat& b, double span)
{
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    double m = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &m);
    const cv::Scalar mean = cv::mean(diff);
    return {(mean[0] + mean[1] + mean[2]) / 3.0 / span, m / span};
}

/// The lens parameter `field` changed by +1 % (or -1 % where +1 % leaves the documented range);
/// nothing when the parameter is 0 or infinite (1 % of those is no change).
std::optional<LensSettings> nudged(const LensSettings& lens, double LensSettings::*field)
{
    if (lens.*field == 0.0 || !std::isfinite(lens.*field))
        return std::nullopt;
    for (const double factor : {1.01, 0.99}) {
        LensSettings changed = lens;
        changed.*field *= factor;
        if (validate(changed).empty())
            return changed;
    }
    return std::nullopt;
}

struct Parameter {
    const char* name;
    double LensSettings::*field;
    bool thinLens;   ///< matters to the thin-lens model
    bool focalRange; ///< matters to the focal-range model
};

constexpr Parameter kParameters[] = {
    {"focus", &LensSettings::focusM, true, true},
    {"f-number", &LensSettings::fNumber, true, false},
    {"focal-length", &LensSettings::focalLengthMm, true, false},
    {"sensor-width", &LensSettings::sensorWidthMm, true, false},
    {"max-coc", &LensSettings::maxCocPx, true, true},
    {"near", &LensSettings::nearLimitM, false, true},
    {"far", &LensSettings::farLimitM, false, true},
};

constexpr View kTargets[] = {View::Input, View::Horizontal, View::DiagonalA, View::DiagonalB};

/// One intermediate target, split into colour (CV_32FC3, BGR like the input) and signed CoC.
struct Target {
    cv::Mat color;
    cv::Mat coc;
};

Target readTarget(Pipeline& pipeline, View view)
{
    std::vector<cv::Mat> rgba;
    cv::split(pipeline.readTarget(view), rgba);
    Target t;
    cv::merge(std::vector<cv::Mat>{rgba[2], rgba[1], rgba[0]}, t.color);
    t.coc = rgba[3];
    return t;
}

struct Rendered {
    Target targets[4]; ///< Input, Horizontal, DiagonalA, DiagonalB
    cv::Mat linear;    ///< composite, CV_32FC3 BGR
    cv::Mat srgb;      ///< composite, CV_8UC3 BGR
};

Rendered renderAll(Pipeline& pipeline, const Frame& frame, const LensSettings& lens, const QualitySettings& quality)
{
    Rendered r;
    r.linear = pipeline.run(frame, lens, quality, View::Composite, Encoding::Linear32F);
    for (int i = 0; i < 4; ++i)
        r.targets[i] = readTarget(pipeline, kTargets[i]);
    r.srgb = pipeline.read(View::Composite, Encoding::Srgb8);
    return r;
}

// Continuity: a 1 % change of one lens parameter, in shares of the input's colour span, measured
// over every case and parameter on llvmpipe (the suite prints the worst at its end).
//  - Any change: mean <= 0.06 (measured 0.040, FocalLength1200mm focus: a 1 % focus change moves
//    the CoC of that long lens by 3 px on average, up to 22 px); max <= 0.6 (measured 0.55,
//    FocalRangeNearLimitJustBeforeFocus focus: a ramp 1e-16 m wide turns the 2 m box from sharp
//    to 32 px). However small the change, a pixel may jump: each discrete step of hex_blur.frag
//    (in-focus threshold, tap thinning; measured alone in BlurSteps below: up to 0.22) can be
//    crossed in the horizontal pass and again in a diagonal one, and the bleeding rule switches
//    a tap's weight between 1 and blurriness * 30; measured up to 0.48 for CoC changes < 0.2 px.
//  - Gentle changes, where no CoC moves by more than 0.25 px: mean <= 0.007. Measured 0.0034
//    with McIntosh's kernel; 0.0052 with the default rhombi (ImageNx1 focus: every pixel sits at
//    a CoC of 1.2 px, where a 0.05 px change moves each neighbour's share of a line by 3 % of
//    the pattern's contrast; the rhombi's box pieces give a 1.2 px blur its full width, the
//    McIntosh taps mostly resample the centre).
constexpr double kContinuityMeanBound = 0.06;
constexpr double kContinuityMaxBound = 0.6;
constexpr double kGentleCocChangePx = 0.25;
constexpr double kGentleMeanBound = 0.007;
// Half-float against full-float targets at 4K with a 64 px CoC: mean <= 0.002 (measured 0.00065),
// max <= 0.1 (measured 0.045: a half float rounds a CoC near 64 px by up to 1/64 px, enough to
// move a pixel across the in-focus threshold or a tap-thinning step here and there).
constexpr double kHalfVsFloatMeanBound = 0.002;
constexpr double kHalfVsFloatMaxBound = 0.1;

/// The worst figures of the suite, printed at its end.
struct Worst {
    Change any, gentle, halfVsFloat;
    std::string anyMeanAt, anyMaxAt, gentleMeanAt;
};

/// Per quality setting ("rhombi", "mcintosh", "high").
std::map<std::string, Worst>& worstByQuality()
{
    static std::map<std::string, Worst> w;
    return w;
}

void keepWorst(double value, double& worstValue, std::string& worstAt, const std::string& at)
{
    if (value > worstValue) {
        worstValue = value;
        worstAt = at;
    }
}

/// The quality setting called `name`: a preset, or a kernel with the plain settings.
QualitySettings namedQuality(std::string name)
{
    name = name.substr(0, name.find('_'));
    for (const auto& q : test::presetsAndKernels())
        if (q.name == name)
            return q.quality;
    ADD_FAILURE() << "no quality setting called " << name;
    return {};
}

/// The aperture a quality name ends in after '_' (the hexagon without): "circle", "nonagon" (9
/// blades turned by 20 degrees), "oval" (a circle squeezed 2:1). The case's own settings come
/// after it, so a case that sets the aperture still does.
void applyAperture(const std::string& name, LensSettings& lens)
{
    const std::string aperture = name.find('_') == std::string::npos ? "" : name.substr(name.find('_') + 1);
    if (aperture == "circle") {
        lens.blades = 0;
    } else if (aperture == "nonagon") {
        lens.blades = 9;
        lens.bladeRotationDeg = 20.0;
    } else if (aperture == "oval") {
        lens.blades = 0;
        lens.apertureRatio = 2.0;
    } else if (!aperture.empty()) {
        ADD_FAILURE() << "no aperture called " << aperture;
    }
}

/// A case and the quality setting it runs with.
using CaseAndQuality = std::tuple<HardCase, std::string>;

std::string caseName(const ::testing::TestParamInfo<CaseAndQuality>& p)
{
    return std::string(std::get<0>(p.param).name) + "_" + std::get<1>(p.param);
}

class HardCases : public test::GLTest, public ::testing::WithParamInterface<CaseAndQuality> {
protected:
    static void TearDownTestSuite()
    {
        for (const auto& [name, w] : worstByQuality())
            std::printf("[ hard cases ] %s: worst 1 %% change: mean %.4f (%s), max %.4f (%s); gentle mean %.4f (%s); "
                        "16F vs 32F at 4K: mean %.5f, max %.4f\n",
                        name.c_str(), w.any.mean, w.anyMeanAt.c_str(), w.any.max, w.anyMaxAt.c_str(), w.gentle.mean,
                        w.gentleMeanAt.c_str(), w.halfVsFloat.mean, w.halfVsFloat.max);
    }
};

/// The presets at half size, by the bounds the upscale guarantees.
class HardCasesHalfSize : public test::GLTest, public ::testing::WithParamInterface<CaseAndQuality> {};

TEST_P(HardCases, FiniteInRangeInFocusKeptAndContinuous)
{
    const HardCase& c = std::get<0>(GetParam());
    const std::string& qualityName = std::get<1>(GetParam());
    Worst& worst = worstByQuality()[qualityName];
    LensSettings lens = baseLens();
    applyAperture(qualityName, lens);
    QualitySettings quality = namedQuality(qualityName);
    if (c.setup)
        c.setup(lens, quality);

    // Settings: either valid as they are, or refused (naming the parameter) and then clamped into
    // something valid.
    {
        LensSettings lensCopy = lens;
        QualitySettings qualityCopy = quality;
        auto issues = validate(lensCopy);
        for (auto& issue : validate(qualityCopy))
            issues.push_back(issue);
        if (!c.rejects) {
            ASSERT_TRUE(issues.empty()) << issues.front().message;
        } else {
            ASSERT_TRUE(std::any_of(issues.begin(), issues.end(),
                                    [&c](const SettingIssue& issue) { return issue.parameter == c.rejects; }))
                << "validate() must refuse " << c.rejects;
            validate(lens, true);
            validate(quality, true);
            lensCopy = lens;
            qualityCopy = quality;
            const auto remaining = validate(lensCopy);
            ASSERT_TRUE(remaining.empty()) << "clamping left: " << remaining.front().message;
            ASSERT_TRUE(validate(qualityCopy).empty());
        }
    }

    // The CoC model the shader evaluates is finite (GLSL leaves clamp() of NaN undefined).
    const CocCoefficients k = cocCoefficients(lens, c.size.width);
    for (const float value : {k.nearScale, k.nearOffset, k.farScale, k.farOffset, k.focusM, k.maxCocPx})
        ASSERT_TRUE(std::isfinite(value)) << "CoC coefficients";

    const Frame frame{makeColor(c.color, c.size), makeDepth(c.depth, c.depthValue, c.size), 0.0, 0, c.name};
    const Reference ref = makeReference(frame.color, quality.targetFormat);
    Pipeline pipeline(false);
    const Rendered out = renderAll(pipeline, frame, lens, quality);

    // Depth reaching the shaders is valid everywhere, whatever came in.
    const cv::Mat& filled = pipeline.filledDepth();
    ASSERT_EQ(filled.size(), c.size);
    int invalid = 0;
    for (int y = 0; y < filled.rows; ++y)
        for (int x = 0; x < filled.cols; ++x)
            invalid += isValidDepth(filled.at<float>(y, x)) ? 0 : 1;
    EXPECT_EQ(invalid, 0) << "filled depth has holes";
    if (c.depth == DepthKind::Holes && !isValidDepth(c.depthValue)) {
        EXPECT_GT(pipeline.invalidDepthFraction(), 0.0);
    }

    // Frames with bokeh sprites: a light in focus goes into the blur as what lies round it, or
    // where only lights do, scaled to the threshold's luminance, hue kept (coc.frag, standIn()),
    // which can leave the input's range in a channel that was small; the output puts the light
    // back (in_focus_light.frag). The targets' pixels of such lights are checked to hold no more
    // than the threshold's luminance below, and left out of the range.
    // In focus: the lens' CoC under half a pixel; the targets hold the gather's, the lens' scaled
    // to the aperture's area (up to 1.1 times, which the rhombi still pass through below 1 px).
    const cv::Mat sharp = cv::abs(out.targets[0].coc) < 0.5f * gatherScale(ApertureShape::of(lens));
    cv::Mat heldBack(c.size, CV_8U, cv::Scalar(0));
    const auto luminance = [](const cv::Vec3f& v) { return 0.2126 * v[2] + 0.7152 * v[1] + 0.0722 * v[0]; };
    if (pipeline.plan().highlightSprites) {
        for (int y = 0; y < c.size.height; ++y)
            for (int x = 0; x < c.size.width; ++x)
                if (std::abs(out.targets[0].coc.at<float>(y, x)) < 1.0f &&
                    luminance(ref.sanitised.at<cv::Vec3f>(y, x)) > HighlightSpritePass::kThreshold)
                    heldBack.at<std::uint8_t>(y, x) = 255;
    }
    // No NaN or Inf anywhere; every target's colour inside the input's range (each pass is a
    // convex combination of its source; composite is a min of two of them); every CoC inside
    // [-max-coc, max-coc] of the gather (the lens' scaled to the aperture's area; the blur
    // averages CoCs too, so this holds after every pass).
    const double maxCoc = lens.maxCocPx * gatherScale(ApertureShape::of(lens));
    const double cocSlack = maxCoc * relativeTolerance(quality.targetFormat) + kAbsoluteTolerance;
    std::string first;
    for (int i = 0; i < 4; ++i) {
        const std::string_view target = viewName(kTargets[i]);
        ASSERT_TRUE(test::allFinite(out.targets[i].color) && test::allFinite(out.targets[i].coc)) << target;
        cv::Mat color = out.targets[i].color.clone();
        ref.sanitised.copyTo(color, heldBack);
        EXPECT_EQ(countOutOfRange(color, ref.lo, ref.hi, ref.loSlack, ref.hiSlack, first), 0)
            << target << ": " << first;
        double lo = 0, hi = 0;
        cv::minMaxLoc(out.targets[i].coc, &lo, &hi);
        EXPECT_GE(lo, -maxCoc - cocSlack) << target;
        EXPECT_LE(hi, maxCoc + cocSlack) << target;
    }
    ASSERT_TRUE(test::allFinite(out.linear)) << "composite";
    EXPECT_EQ(countOutOfRange(out.linear, ref.lo, ref.hi, ref.loSlack, ref.hiSlack, first), 0) << "composite: " << first;
    // sRGB8: the encode on the GPU may round the other way than the CPU's: one 8-bit step.
    EXPECT_EQ(countOutOfRange(out.srgb, ref.lo8, ref.hi8, cv::Vec3d::all(1.0), cv::Vec3d::all(1.0), first), 0)
        << "composite sRGB8: " << first;

    // In focus (|CoC| < 0.5 px): both kernels pass the centre texel through (hex_blur.frag below
    // 0.5 px, rhombus_blur.frag below 1 px), so every later target holds exactly the Input
    // target's colour; that colour and the composite's are the input (or its sanitised form) up
    // to one half-float rounding and the driver's sRGB decode (slack() above), and in sRGB8 at
    // most one step away (decode -> half -> encode, as PassesGLTest's ZeroCocReturnsTheInput).
    const int inFocusCount = cv::countNonZero(sharp);
    if (c.blur == Blur::None) {
        EXPECT_EQ(inFocusCount, c.size.area()) << "every pixel should be in focus";
    }
    if (c.blur == Blur::Some) {
        EXPECT_LT(inFocusCount, c.size.area()) << "the case must blur something";
    }
    // With the near field (the high preset), blurred foreground spreads over what lies behind it,
    // in focus or not, by design: the tiles the foreground can reach (their lines run as far as
    // it, rhombus_blur.frag NEAR_FIELD) are left out of the in-focus checks. The colour range
    // above holds there too: foreground and background mix by coverage.
    cv::Mat inFocus = sharp.clone();
    if (quality.nearField && !pipeline.plan().allInFocus) {
        const SceneAnalysis& analysis = pipeline.analysis();
        constexpr int T = SceneAnalysis::kTileSize;
        for (int ty = 0; ty < analysis.tiles.height; ++ty)
            for (int tx = 0; tx < analysis.tiles.width; ++tx)
                if (analysis.tileNearDiameter.at<float>(ty, tx) >= 1.0f)
                    inFocus(cv::Rect(tx * T, ty * T, T, T) & cv::Rect({0, 0}, c.size)).setTo(0);
    }
    for (int i = 1; i < 4; ++i)
        EXPECT_EQ(maxRgbDifference(out.targets[i].color, out.targets[0].color, inFocus), 0.0) << viewName(kTargets[i]);
    EXPECT_EQ(cv::countNonZero(differsBeyond(out.targets[0].color, ref.sanitised, ref.sanitisedSlack) & inFocus &
                               ~heldBack),
              0)
        << "in-focus colour changed (Input target)";
    int notHeldBack = 0;
    for (int y = 0; y < c.size.height; ++y)
        for (int x = 0; x < c.size.width; ++x)
            notHeldBack += heldBack.at<std::uint8_t>(y, x) != 0 &&
                           luminance(out.targets[0].color.at<cv::Vec3f>(y, x)) > HighlightSpritePass::kThreshold * 1.0001;
    EXPECT_EQ(notHeldBack, 0) << "a light in focus entered the blur above the threshold (Input target)";
    EXPECT_EQ(cv::countNonZero(differsBeyond(out.linear, ref.sanitised, ref.sanitisedSlack) &
                               differsBeyond(out.linear, ref.raw, ref.rawSlack) & inFocus),
              0)
        << "in-focus colour changed (composite, linear)";
    const cv::Mat oneStep(c.size, CV_8UC3, cv::Scalar::all(1));
    EXPECT_EQ(cv::countNonZero(differsBeyond(out.srgb, ref.srgb, oneStep) & differsBeyond(out.srgb, ref.srgbRaw, oneStep) &
                               inFocus),
              0)
        << "in-focus colour changed (composite, sRGB8)";
    if (c.unchanged) {
        EXPECT_EQ(maxRgbDifference(out.linear, out.targets[0].color, cv::Mat()), 0.0) << "the composite must be the input";
    }

    if (c.compareWith32F && quality.targetFormat == TargetFormat::Rgba16F) { // the high preset is 32F already
        QualitySettings full = quality;
        full.targetFormat = TargetFormat::Rgba32F;
        const cv::Mat reference = pipeline.run(frame, lens, full, View::Composite, Encoding::Linear32F);
        const Change d = relativeChange(out.linear, reference, ref.span);
        worst.halfVsFloat = d;
        EXPECT_LE(d.mean, kHalfVsFloatMeanBound);
        EXPECT_LE(d.max, kHalfVsFloatMaxBound);
    }

    if (!c.continuity)
        return;
    for (const Parameter& p : kParameters) {
        if (!(lens.model == CocModel::ThinLens ? p.thinLens : p.focalRange))
            continue;
        const auto changed = nudged(lens, p.field);
        if (!changed)
            continue;
        const cv::Mat moved = pipeline.run(frame, *changed, quality, View::Composite, Encoding::Linear32F);
        ASSERT_TRUE(test::allFinite(moved)) << p.name;
        const Change d = relativeChange(out.linear, moved, ref.span);
        cv::Mat cocChange;
        cv::absdiff(readTarget(pipeline, View::Input).coc, out.targets[0].coc, cocChange);
        double largestCocChange = 0;
        cv::minMaxLoc(cocChange, nullptr, &largestCocChange);
        const std::string at = std::string(c.name) + " " + p.name;
        keepWorst(d.mean, worst.any.mean, worst.anyMeanAt, at);
        keepWorst(d.max, worst.any.max, worst.anyMaxAt, at);
        EXPECT_LE(d.mean, kContinuityMeanBound) << p.name;
        EXPECT_LE(d.max, kContinuityMaxBound) << p.name;
        if (largestCocChange <= kGentleCocChangePx) {
            keepWorst(d.mean, worst.gentle.mean, worst.gentleMeanAt, at);
            EXPECT_LE(d.mean, kGentleMeanBound) << p.name << ": CoC moved by at most " << largestCocChange << " px";
        }
    }
}

// The same cases through the half-size presets (balanced, the default, and fast): one render
// each. The output has the frame's size and is finite. Its bounds are what upscale.frag can
// give (lo, hi: the range of the input, sanitised):
//  - a pixel blurred by 2 px or more is the interpolation of the prefiltered blur, which
//    upscale_prefilter.frag clamps to its neighbourhood's range of the blur, itself within the
//    input's range: inside [lo, hi], as at full size;
//  - a pixel under 2 px of CoC keeps the frame's own value plus what the blur added around it
//    (frame + bil(R - C)), at most hi + (hi - lo) and at least max(0, lo - (hi - lo)).
// (Before the prefilter's clamp, its overshoot took blurred pixels past the input's range too,
// and the bound was twice the input's largest value everywhere.)
TEST_P(HardCasesHalfSize, FiniteFrameSizedAndWithinWhatTheUpscaleCanGive)
{
    const HardCase& c = std::get<0>(GetParam());
    LensSettings lens = baseLens();
    applyAperture(std::get<1>(GetParam()), lens);
    QualitySettings quality = namedQuality(std::get<1>(GetParam()));
    ASSERT_EQ(quality.resolution, Resolution::Half);
    if (c.setup)
        c.setup(lens, quality);
    validate(lens, true);
    validate(quality, true);
    const Frame frame{makeColor(c.color, c.size), makeDepth(c.depth, c.depthValue, c.size), 0.0, 0, c.name};
    const Reference ref = makeReference(frame.color, quality.targetFormat);
    Pipeline pipeline(false);
    const cv::Mat linear = pipeline.run(frame, lens, quality, View::Composite, Encoding::Linear32F);
    ASSERT_EQ(linear.size(), c.size);
    ASSERT_TRUE(test::allFinite(linear));

    // The frame's CoC, as upscale.frag computes it from the filled depth (the gather's: the lens'
    // scaled to the aperture's area); pixels within 1 % of the 2 px edge count as under it (the
    // shader's float maths may round the other way).
    const CocCoefficients k = scaled(cocCoefficients(lens, c.size.width), gatherScale(ApertureShape::of(lens)));
    const cv::Mat& depth = pipeline.filledDepth();
    cv::Mat blurred(c.size, CV_8U);
    for (int y = 0; y < c.size.height; ++y)
        for (int x = 0; x < c.size.width; ++x)
            blurred.at<std::uint8_t>(y, x) =
                std::abs(cocPixels(k, depth.at<float>(y, x))) >= 1.01f * kUpscaleDetailBelowPx ? 255 : 0;
    std::string first;
    EXPECT_EQ(countOutOfRange(linear.clone().setTo(cv::Scalar(ref.lo), ~blurred), ref.lo, ref.hi, ref.loSlack,
                              ref.hiSlack, first),
              0)
        << "blurred by 2 px or more: " << first;
    const cv::Vec3d span = ref.hi - ref.lo;
    cv::Vec3d keptLo, keptHi;
    for (int i = 0; i < 3; ++i) {
        keptLo[i] = std::max(0.0, ref.lo[i] - span[i]);
        keptHi[i] = ref.hi[i] + span[i];
    }
    EXPECT_EQ(countOutOfRange(linear.clone().setTo(cv::Scalar(keptLo), blurred), keptLo, keptHi, 2.0 * ref.loSlack,
                              2.0 * ref.hiSlack, first),
              0)
        << "under 2 px of CoC: " << first;
    EXPECT_EQ(pipeline.read(View::Composite, Encoding::Srgb8).size(), c.size);
    const cv::Mat input = pipeline.readTarget(View::Input);
    EXPECT_EQ(input.size(), cv::Size((c.size.width + 1) / 2, (c.size.height + 1) / 2));
    EXPECT_TRUE(test::allFinite(input));
}

INSTANTIATE_TEST_SUITE_P(EveryCase, HardCases,
                         ::testing::Combine(::testing::ValuesIn(kCases), ::testing::Values("rhombi", "mcintosh", "high")),
                         caseName);
INSTANTIATE_TEST_SUITE_P(EveryCase, HardCasesHalfSize,
                         ::testing::Combine(::testing::ValuesIn(kCases), ::testing::Values("balanced", "fast")),
                         caseName);
// Other apertures: their sprites and the gather's scaled CoC on every hostile input.
INSTANTIATE_TEST_SUITE_P(EveryAperture, HardCases,
                         ::testing::Combine(::testing::ValuesIn(kCases), ::testing::Values("rhombi_circle", "high_nonagon")),
                         caseName);
INSTANTIATE_TEST_SUITE_P(EveryAperture, HardCasesHalfSize,
                         ::testing::Combine(::testing::ValuesIn(kCases), ::testing::Values("balanced_oval")), caseName);

// The blur's two discrete steps, each measured alone on a uniform CoC D (focal range, every
// depth beyond the far limit, so c = max-coc everywhere and the bleeding rule never acts):
//  - the in-focus threshold: below 0.5 px a pass copies the pixel; just above it averages two
//    taps at +-D/2 = +-0.25 px, each bilinearly 3/4 the centre and 1/4 a neighbour, so a pass
//    moves the pixel by a quarter of its contrast with its neighbours;
//  - tap thinning: with 16 samples (15 intervals) the stride is the largest of 15, 5, 3, 1 with
//    D * stride <= 1.5 px * 15, so the taps used go 2 -> 4 -> 6 -> 16 at D = 1.5, 4.5, 7.5 px.
// Between steps a 0.4 % change of D barely moves the output. Measured on the 6 px checkerboard
// with noise (mean / max, shares of the colour span): threshold 0.048 / 0.218; 2 -> 4 taps
// 0.027 / 0.117; 4 -> 6 taps 0.011 / 0.053; 6 -> 16 taps 0.013 / 0.051; between steps
// 0.0004 / 0.0025. The bounds below add about 50 % (the between-steps one, 4x).
class BlurSteps : public test::GLTest {};

TEST_F(BlurSteps, InFocusThresholdAndTapThinningJumpsAreBounded)
{
    const cv::Size size(64, 48);
    const cv::Mat color = linearPattern(size);
    const Frame frame{color, cv::Mat(size, CV_32F, cv::Scalar(3.0f)), 0.0, 0, "steps"};
    const Reference ref = makeReference(color, TargetFormat::Rgba16F);
    Pipeline pipeline(false);
    QualitySettings mcintosh; // the kernel with the steps; the rhombi have none (below)
    mcintosh.kernel = HexagonKernel::McIntoshMin;
    const auto render = [&](double diameter, const QualitySettings& quality) {
        LensSettings lens;
        lens.model = CocModel::FocalRange;
        lens.focusM = 1.0;
        lens.nearLimitM = 0.5;
        lens.farLimitM = 2.0;
        lens.maxCocPx = diameter;
        return pipeline.run(frame, lens, quality, View::Composite, Encoding::Linear32F);
    };
    struct Step {
        const char* what;
        double diameter;
        double meanBound, maxBound; // from the measurements in the comment, with margin
    };
    const Step steps[] = {
        {"in-focus threshold", 0.5, 0.07, 0.33},
        {"2 -> 4 taps", 1.5, 0.04, 0.18},
        {"4 -> 6 taps", 4.5, 0.02, 0.08},
        {"6 -> 16 taps", 7.5, 0.02, 0.08},
        {"between steps", 3.0, 0.002, 0.01},
    };
    for (const Step& step : steps) {
        // +-0.2 %: far enough apart to land on both sides of the step after the CoC is stored
        // as a half float (spacing 2^-11 of the value).
        const Change d = relativeChange(render(step.diameter * 0.998, mcintosh), render(step.diameter * 1.002, mcintosh),
                                        ref.span);
        std::printf("[ blur steps ] %s at %.1f px: mean %.4f, max %.4f\n", step.what, step.diameter, d.mean, d.max);
        EXPECT_LE(d.mean, step.meanBound) << step.what;
        EXPECT_LE(d.max, step.maxBound) << step.what;
        // The rhombi at the same diameters: no step (their lines are weighted pieces, continuous
        // in the CoC), so +-0.2 % of the CoC moves them as little as between McIntosh's steps:
        // measured mean <= 0.0006, max <= 0.0027 (at 0.5 px: half-float rounding only, the
        // rhombi leave |CoC| < 1 px alone).
        const QualitySettings rhombi;
        const Change r = relativeChange(render(step.diameter * 0.998, rhombi), render(step.diameter * 1.002, rhombi),
                                        ref.span);
        std::printf("[ blur steps ] rhombi at %.1f px: mean %.4f, max %.4f\n", step.diameter, r.mean, r.max);
        EXPECT_LE(r.mean, 0.002) << "rhombi at " << step.diameter;
        EXPECT_LE(r.max, 0.01) << "rhombi at " << step.diameter;
    }
}

} // namespace
} // namespace defocus
