// SPDX-License-Identifier: LGPL-2.1-or-later
// Pipeline methods: one Pipeline run, read back as linear float, with this frame's GPU times.
#include "bench/methods/PipelineMethod.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace defocus {

bool PipelineMethod::handles(std::string_view name)
{
    return name == "mcintosh" || name == "mcintosh-near" || name == "rhombi" || name == "rhombi-near";
}

PipelineMethod::PipelineMethod(std::string_view name, bool timers)
    : info_(*findMethod(name)), pipeline_(timers)
{
}

QualitySettings PipelineMethod::quality(std::string_view name, const MethodSettings& settings)
{
    if (!handles(name))
        throw std::invalid_argument(fmt::format("defocus::PipelineMethod: no pipeline method called '{}'", name));
    QualitySettings quality;
    quality.kernel = name.starts_with("rhombi") ? HexagonKernel::RhombiSum : HexagonKernel::McIntoshMin;
    quality.nearField = name.ends_with("-near");
    quality.samples = settings.samples;
    quality.targetFormat = settings.precision;
    quality.resolution = settings.resolution;
    quality.adaptive = settings.adaptive;
    quality.highlightSprites = settings.highlightSprites;
    quality.quarterOnLargeBlur = settings.quarterOnLargeBlur;
    return quality;
}

MethodResult PipelineMethod::process(const Frame& frame, const LensSettings& lens, const MethodSettings& settings)
{
    MethodResult result;
    result.linear = pipeline_.run(frame, lens, quality(info_.name, settings), View::Composite, Encoding::Linear32F);
    // read() has swapped the timer sets; draining now returns this frame's scopes (the readback
    // has waited for the GPU already).
    result.gpu = pipeline_.drainGpuTimes();
    return result;
}

} // namespace defocus
