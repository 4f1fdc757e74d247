// SPDX-License-Identifier: LGPL-2.1-or-later
// Thin-lens and focal-range CoC coefficients.
#include "filter/Lens.hpp"

#include <algorithm>
#include <cmath>

namespace defocus {

CocCoefficients cocCoefficients(const LensSettings& lens, int imageWidthPx)
{
    CocCoefficients k;
    k.maxCocPx = static_cast<float>(lens.maxCocPx);
    k.focusM = static_cast<float>(std::min(lens.focusM, 1e30));
    const double pixelsPerMetreOnSensor = imageWidthPx / (lens.sensorWidthMm * 1e-3);

    if (lens.model == CocModel::ThinLens) {
        // With f the focal length, N the f-number, A = f / N the aperture diameter, S1 the focus
        // distance and S2 = z the depth (all in metres), a point at z blurs into a disc of
        // diameter A |z - S1| / z on the focus plane (similar triangles through the aperture),
        // which the sensor at distance d behind the lens sees d / S1 times as large:
        //   c = A (z - S1) / z * d / S1
        // With the sensor at the image distance d = v = f S1 / (S1 - f), this is the textbook
        //   c = A (z - S1) / z * f / (S1 - f)
        //     = A f / (S1 - f)  -  A f S1 / (S1 - f) * (1 / z)
        // so c = K0 * (1/z) + K1 with K1 = A f / (S1 - f) and K0 = -K1 * S1, times pixels per
        // metre of sensor; with the field of view from the focal length (d = f), K1 = A f / S1.
        // As S1 -> inf, K1 -> 0 and K0 -> -A f in both: everything is in front of focus.
        const double f = lens.focalLengthMm * 1e-3;
        const double aperture = f / lens.fNumber;
        double k0 = 0.0, k1 = 0.0;
        if (std::isinf(lens.focusM)) {
            k0 = -aperture * f;
        } else {
            const double sensorDistanceOverFocus = lens.fieldOfView == FieldOfView::ImageDistance
                                                       ? f / (lens.focusM - f)
                                                       : f / lens.focusM;
            k1 = aperture * sensorDistanceOverFocus;
            k0 = -k1 * lens.focusM;
        }
        k.nearScale = k.farScale = static_cast<float>(k0 * pixelsPerMetreOnSensor);
        k.nearOffset = k.farOffset = static_cast<float>(k1 * pixelsPerMetreOnSensor);
        k.inverseDepth = true;
    } else {
        // Linear ramps in z: c = -max (S1 - z) / (S1 - near) in front, max (z - S1) / (far - S1)
        // behind, i.e. c = s * z + o with s = max / (S1 - near), o = -s * S1 (and likewise far).
        // With the focus at infinity the near ramp's limit is flat: c = -max for every finite z
        // (computing it directly would give 0 * inf = NaN).
        k.inverseDepth = false;
        if (std::isinf(lens.focusM)) {
            k.nearOffset = -k.maxCocPx;
        } else {
            const double nearScale = lens.maxCocPx / (lens.focusM - lens.nearLimitM);
            k.nearScale = static_cast<float>(nearScale);
            k.nearOffset = static_cast<float>(-nearScale * lens.focusM);
        }
        if (!std::isinf(lens.farLimitM)) {
            const double farScale = lens.maxCocPx / (lens.farLimitM - lens.focusM);
            k.farScale = static_cast<float>(farScale);
            k.farOffset = static_cast<float>(-farScale * lens.focusM);
        }
    }
    return k;
}

double thinLensCocPixels(const LensSettings& lens, int imageWidthPx, double depthM)
{
    const double f = lens.focalLengthMm * 1e-3;
    const double A = f / lens.fNumber;
    const double S1 = lens.focusM;
    const double S2 = depthM;
    const double sensorDistance = lens.fieldOfView == FieldOfView::ImageDistance ? f * S1 / (S1 - f) : f;
    const double c = A * std::abs(S2 - S1) / S2 * sensorDistance / S1;
    const double signedC = S2 < S1 ? -c : c;
    return signedC * imageWidthPx / (lens.sensorWidthMm * 1e-3);
}

} // namespace defocus
