// SPDX-License-Identifier: LGPL-2.1-or-later
// The registry of depth-of-field methods that the accuracy benchmark compares: each method is a
// named chain of passes (or the CPU reference) behind one interface, with the same knobs (sample
// count, resolution scale, render-target precision) and the same output: linear float colour,
// GPU time per pass and wall time per frame.
//   auto method = createMethod("riguer");           // needs a current GL context for GPU methods
//   MethodResult r = method->run(frame, lens, {12, Resolution::Full, TargetFormat::Rgba16F});
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "defocus/Frame.hpp"
#include "filter/Pipeline.hpp"
#include "filter/Settings.hpp"

namespace defocus {

struct MethodSettings {
    /// Taps per pass. McIntosh: [2, 64] per directional pass. Fixed by the kernel for riguer (12),
    /// lazy8 (8) and gaussian5x5 (25), and ignored by the references; MethodInfo::samples lists
    /// what each accepts.
    int samples = 16;
    /// Full, or half. The pipeline methods (mcintosh, rhombi) blur at half size themselves
    /// (QualitySettings::resolution: the output keeps the frame's in-focus pixels). For the
    /// others, Method::run() scales on the CPU, in the wall time: colour made linear, sanitised
    /// and area-averaged to (w + 1) / 2 x (h + 1) / 2, depth resized by nearest neighbour (no
    /// depth invented at edges), max-coc halved (CoC in pixels halves with the width), and the
    /// output upscaled bilinearly.
    Resolution resolution = Resolution::Full;
    /// Precision of the intermediate and output render targets of GPU methods.
    TargetFormat precision = TargetFormat::Rgba16F;
    /// The rhombi: bokeh sprites for lights (QualitySettings::highlightSprites).
    bool highlightSprites = true;
    /// The pipeline methods: follow the per-frame plan (QualitySettings::adaptive); false runs
    /// every pass on every pixel, all-in-focus frames included. Ignored by the other methods,
    /// which always run every pass.
    bool adaptive = true;
    /// The pipeline methods at half size: quarter size on frames whose blur is large
    /// (QualitySettings::quarterOnLargeBlur); false: always half size.
    bool quarterOnLargeBlur = false;
};

std::string_view precisionName(TargetFormat format);    ///< "16F", "32F"

struct MethodInfo {
    std::string_view name;  ///< registry key, e.g. "mcintosh"
    std::string_view title; ///< one line for tables and plots
    bool gpu = true;        ///< false: CPU only, needs no GL context
    /// The sample counts the benchmark sweeps; a fixed kernel lists its one count.
    std::vector<int> samples;
    /// Accepted range of MethodSettings::samples (equal bounds for a fixed kernel).
    int minSamples = 0, maxSamples = 0;
};

/// "mcintosh 16 full 16F"; the references print "reference" (and their variant) only.
std::string describe(const MethodInfo& info, const MethodSettings& settings);

struct MethodResult {
    cv::Mat linear;            ///< CV_32FC3 BGR, frame-sized, scene-linear (unclipped)
    std::vector<PassTime> gpu; ///< GPU ms per pass of this frame; empty without timer queries and for CPU methods
    double wallMs = 0.0;       ///< the whole frame on the wall clock, readback included
};

class Method {
public:
    virtual ~Method() = default;
    virtual const MethodInfo& info() const = 0;
    /// Runs on one frame (Frame conventions: 8-bit sRGB or float linear BGR, depth in metres
    /// with holes allowed). `lens` must have passed validate(); `settings.samples` must lie in
    /// info()'s range (asserted).
    MethodResult run(const Frame& frame, const LensSettings& lens, const MethodSettings& settings);

protected:
    /// true: process() runs at settings.resolution itself, and run() adds no CPU scaling.
    virtual bool scalesItself() const { return false; }
    /// Runs at the frame's own size (or at settings.resolution, when scalesItself()); run()
    /// adds the half-resolution wrapper and the wall time.
    virtual MethodResult process(const Frame& frame, const LensSettings& lens, const MethodSettings& settings) = 0;
};

/// The camera of data/blender_spheres, the scene the registry is measured on
/// (../shared/data/README.md): thin lens, 85 mm, f/1.4, focus 5 m, 36 mm sensor width, the field
/// of view from the focal length as Cycles has it; max-coc 64 px, above the scene's largest CoC
/// at 640 px (45.8 px), so nothing is clamped.
LensSettings blenderSpheresLens();

/// Every method, in table order: mcintosh, riguer, lazy8, gaussian5x5, reference, reference-pointy.
const std::vector<MethodInfo>& methodRegistry();
/// The registry entry called `name`, or nullptr.
const MethodInfo* findMethod(std::string_view name);
/// Creates the method called `name`. GPU methods need a current GL context and compile their
/// shaders here (throws gl::ShaderError); `timers`: use GL timer queries where the driver has
/// them. Throws std::invalid_argument for an unknown name.
std::unique_ptr<Method> createMethod(std::string_view name, bool timers = true);

} // namespace defocus
