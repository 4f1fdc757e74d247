// SPDX-License-Identifier: LGPL-2.1-or-later
// Reference method: filled depth -> CoC map -> exact polygon scatter, all on the CPU.
#include "bench/methods/ReferenceMethod.hpp"

#include <cassert>
#include <cmath>

#include "bench/Metrics.hpp"
#include "filter/ColorSpace.hpp"
#include "filter/DepthPrep.hpp"
#include "filter/Lens.hpp"
#include "filter/passes/CocParams.hpp"

namespace defocus {

ReferenceMethod::ReferenceMethod(std::string_view name) : info_(findMethod(name))
{
    assert(info_ && !info_->gpu);
    if (name == "reference")
        options_.rotationDeg = 30.0f; // flat top and bottom, as --blade-rotation 30
}

MethodResult ReferenceMethod::process(const Frame& frame, const LensSettings& lens, const MethodSettings&)
{
    CV_Assert(!frame.color.empty() && (frame.color.type() == CV_8UC3 || frame.color.type() == CV_32FC3));
    const float fallback = std::isinf(lens.focusM) ? 1e6f : static_cast<float>(lens.focusM);
    const PreparedDepth prepared = prepareDepth(frame.depth, frame.color.size(), fallback);
    const cv::Mat coc = cocMap(prepared.metres, cocCoefficients(lens, frame.color.cols));
    // The same clean-up the CoC pass applies to a full-float target.
    const cv::Mat linear = frame.color.type() == CV_8UC3 ? decodeSrgb(frame.color)
                                                         : sanitizeLinear(frame.color, CocParams::largestColor(false));
    MethodResult result;
    result.linear = referenceScatter(linear, coc, options_);
    return result;
}

} // namespace defocus
