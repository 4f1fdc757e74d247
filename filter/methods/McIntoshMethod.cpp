// McIntosh method: one Pipeline run, read back as linear float, with this frame's GPU times.
#include "filter/methods/McIntoshMethod.hpp"

namespace defocus {

QualitySettings McIntoshMethod::quality(const MethodSettings& settings)
{
    QualitySettings quality;
    quality.samples = settings.samples;
    quality.targetFormat = settings.precision;
    quality.adaptive = true;
    return quality;
}

MethodResult McIntoshMethod::process(const Frame& frame, const LensSettings& lens, const MethodSettings& settings)
{
    MethodResult result;
    result.linear = pipeline_.run(frame, lens, quality(settings), View::Composite, Encoding::Linear32F);
    // read() has swapped the timer sets; draining now returns this frame's scopes (the readback
    // has waited for the GPU already).
    result.gpu = pipeline_.drainGpuTimes();
    return result;
}

} // namespace defocus
