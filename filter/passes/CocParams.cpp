// SPDX-License-Identifier: LGPL-2.1-or-later
#include "filter/passes/CocParams.hpp"

#include <limits>

#include "filter/passes/HexBlurPass.hpp"

namespace defocus {

namespace {

// The largest colour a target keeps. Half float: its maximum. Full float: small enough that
// hex_blur.frag's sum of up to kMaxSamples taps cannot overflow to +Inf before it is divided.
constexpr float kLargestHalf = 65504.0f;
constexpr float kLargestFloat = std::numeric_limits<float>::max() / HexBlurPass::kMaxSamples;

} // namespace

float CocParams::largestColor(bool halfTarget)
{
    return halfTarget ? kLargestHalf : kLargestFloat;
}

CocParams::Block CocParams::block(const CocCoefficients& k, bool halfTarget, float highlightGain,
                                  float highlightThreshold)
{
    return {{k.nearScale, k.nearOffset, k.farScale, k.farOffset},
            k.focusM,
            k.maxCocPx,
            k.inverseDepth ? 1 : 0,
            largestColor(halfTarget),
            highlightGain,
            highlightThreshold};
}

CocParams::CocParams(std::string_view label) : buffer_(sizeof(Block), label) {}

void CocParams::set(const CocCoefficients& k, bool halfTarget, float highlightGain, float highlightThreshold)
{
    values_ = block(k, halfTarget, highlightGain, highlightThreshold);
    buffer_.update(&values_, sizeof values_);
}

} // namespace defocus
