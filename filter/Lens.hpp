// SPDX-License-Identifier: LGPL-2.1-or-later
// The lens model: signed circle-of-confusion diameter in pixels as a function of depth.
// The CPU derives two multiply-add coefficients; the CoC shader only evaluates them.
#pragma once

#include <algorithm>

#include "filter/Settings.hpp"

namespace defocus {

/// c(z) = scale * x + offset with x = 1/z (thin lens) or x = z (focal range), using the near
/// pair for z < focusM and the far pair otherwise; then clamped to [-maxCocPx, maxCocPx].
/// Negative c is in front of the focus plane, positive behind it.
struct CocCoefficients {
    float nearScale = 0.0f;
    float nearOffset = 0.0f;
    float farScale = 0.0f;
    float farOffset = 0.0f;
    float focusM = 1.0f;
    float maxCocPx = 0.0f;
    bool inverseDepth = true;
};

/// Derives the coefficients for an image `imageWidthPx` wide (the width spans the sensor).
/// `lens` must have passed validate().
CocCoefficients cocCoefficients(const LensSettings& lens, int imageWidthPx);

/// `k` with every CoC it gives (and its clamp) multiplied by `scale`.
inline CocCoefficients scaled(CocCoefficients k, float scale)
{
    k.nearScale *= scale;
    k.nearOffset *= scale;
    k.farScale *= scale;
    k.farOffset *= scale;
    k.maxCocPx *= scale;
    return k;
}

/// Evaluates the model exactly as the shader does (for tests and CPU tools; inline, for the
/// scene analysis' per-pixel loop).
inline float cocPixels(const CocCoefficients& k, float depthM)
{
    const float x = k.inverseDepth ? 1.0f / depthM : depthM;
    const float c = depthM < k.focusM ? k.nearScale * x + k.nearOffset : k.farScale * x + k.farOffset;
    return std::clamp(c, -k.maxCocPx, k.maxCocPx);
}

/// The thin-lens CoC in pixels before clamping, straight from the textbook formula
/// c = A |S2 - S1| / S2 * f / (S1 - f) (with the field of view from the focal length,
/// c = A |S2 - S1| / S2 * f / S1), signed; a reference for the derived coefficients.
double thinLensCocPixels(const LensSettings& lens, int imageWidthPx, double depthM);

} // namespace defocus
