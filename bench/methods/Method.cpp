// SPDX-License-Identifier: LGPL-2.1-or-later
// The method registry, the half-resolution wrapper and the wall clock shared by every method.
#include "bench/methods/Method.hpp"

#include <cassert>
#include <chrono>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "bench/methods/GatherMethods.hpp"
#include "bench/methods/PipelineMethod.hpp"
#include "bench/methods/ReferenceMethod.hpp"
#include "filter/ColorSpace.hpp"
#include "filter/passes/CocParams.hpp"

namespace defocus {

std::string_view precisionName(TargetFormat format)
{
    return format == TargetFormat::Rgba16F ? "16F" : format == TargetFormat::Rgba32F ? "32F" : "auto";
}

std::string describe(const MethodInfo& info, const MethodSettings& settings)
{
    if (!info.gpu)
        return std::string(info.name);
    return fmt::format("{} {} {} {}", info.name, settings.samples, resolutionName(settings.resolution),
                       precisionName(settings.precision));
}

LensSettings blenderSpheresLens()
{
    LensSettings lens;
    lens.model = CocModel::ThinLens;
    lens.focalLengthMm = 85.0;
    lens.fNumber = 1.4;
    lens.focusM = 5.0;
    lens.sensorWidthMm = 36.0;
    // Cycles takes the field of view from the focal length (docs/synthetic.md measured its
    // bokeh at 0.980 of the lens formula's; (S - f) / S = 0.983).
    lens.fieldOfView = FieldOfView::FocalLength;
    lens.maxCocPx = 64.0;
    return lens;
}

const std::vector<MethodInfo>& methodRegistry()
{
    static const std::vector<MethodInfo> registry{
        {"mcintosh", "McIntosh et al. 2012 hexagonal chain (blurs along three edges, min)", true,
         {4, 8, 12, 16, 24, 32, 48}, limits::kSamples[0], limits::kSamples[1]},
        {"mcintosh-near", "the same with a blurred foreground layer over it", true, {16, 48}, limits::kSamples[0],
         limits::kSamples[1]},
        {"rhombi", "three one-sided rhombi summed: flat hexagon, paper's bleeding rule", true, {4, 6, 8, 12},
         limits::kSamples[0], limits::kSamples[1]},
        {"rhombi-near", "the same, foreground counted by its own CoC (scatter as gather)", true, {4, 5, 6, 8, 12, 16},
         limits::kSamples[0], limits::kSamples[1]},
        {"riguer", "Riguer et al. 2004 12-tap Poisson disc with their bleeding rule", true, {12}, 12, 12},
        {"lazy8", "8-point lazy gather with a blurriness-difference threshold", true, {8}, 8, 8},
        {"gaussian5x5", "5x5 Gaussian spread by |CoC| (distance from the plane in focus)", true, {25}, 25, 25},
        {"reference", "CPU scatter of exact hexagons (flat top), depth-layered, normalised", false, {0}, 0, 64},
        {"reference-pointy", "the same with a corner on top (Blender Cycles' blade rotation 0)", false, {0}, 0, 64},
    };
    return registry;
}

const MethodInfo* findMethod(std::string_view name)
{
    for (const MethodInfo& info : methodRegistry())
        if (info.name == name)
            return &info;
    return nullptr;
}

const MethodInfo& RiguerMethod::info() const
{
    return *findMethod("riguer");
}

const MethodInfo& LazyMethod::info() const
{
    return *findMethod("lazy8");
}

const MethodInfo& GaussianMethod::info() const
{
    return *findMethod("gaussian5x5");
}

std::unique_ptr<Method> createMethod(std::string_view name, bool timers)
{
    if (PipelineMethod::handles(name))
        return std::make_unique<PipelineMethod>(name, timers);
    if (name == "riguer")
        return std::make_unique<RiguerMethod>(timers);
    if (name == "lazy8")
        return std::make_unique<LazyMethod>(timers);
    if (name == "gaussian5x5")
        return std::make_unique<GaussianMethod>(timers);
    if (name == "reference" || name == "reference-pointy")
        return std::make_unique<ReferenceMethod>(name);
    throw std::invalid_argument(fmt::format("defocus::createMethod: no method called '{}'", name));
}

MethodResult Method::run(const Frame& frame, const LensSettings& lens, const MethodSettings& settings)
{
    assert(settings.samples >= info().minSamples && settings.samples <= info().maxSamples);
    const auto start = std::chrono::steady_clock::now();
    MethodResult result;
    if (settings.resolution == Resolution::Full || scalesItself()) {
        result = process(frame, lens, settings);
    } else {
        CV_Assert(frame.color.type() == CV_8UC3 || frame.color.type() == CV_32FC3);
        const cv::Size full = frame.color.size();
        const cv::Size half((full.width + 1) / 2, (full.height + 1) / 2);
        // Average light, not sRGB codes: decode first; and no NaN/Inf may reach the average.
        const cv::Mat linear = frame.color.type() == CV_8UC3
                                   ? decodeSrgb(frame.color)
                                   : sanitizeLinear(frame.color, CocParams::largestColor(
                                                                     settings.precision == TargetFormat::Rgba16F));
        Frame small = frame;
        cv::resize(linear, small.color, half, 0.0, 0.0, cv::INTER_AREA);
        if (!frame.depth.empty())
            cv::resize(frame.depth, small.depth, half, 0.0, 0.0, cv::INTER_NEAREST);
        LensSettings halfLens = lens;
        halfLens.maxCocPx = lens.maxCocPx / 2.0;
        result = process(small, halfLens, settings);
        cv::Mat upscaled;
        cv::resize(result.linear, upscaled, full, 0.0, 0.0, cv::INTER_LINEAR);
        result.linear = upscaled;
    }
    result.wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace defocus
