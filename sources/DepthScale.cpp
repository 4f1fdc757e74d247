// SPDX-License-Identifier: LGPL-2.1-or-later
// The depth-scale plausibility check: median valid depth against what sensors measure.
#include "sources/DepthScale.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

namespace defocus {

DepthScaleCheck checkDepthScale(const cv::Mat& depthMetres, double unitsPerMetre, const std::string& where)
{
    DepthScaleCheck check;
    if (depthMetres.empty() || depthMetres.type() != CV_32FC1)
        return check;
    std::vector<float> valid;
    valid.reserve(depthMetres.total());
    for (int y = 0; y < depthMetres.rows; ++y) {
        const float* row = depthMetres.ptr<float>(y);
        for (int x = 0; x < depthMetres.cols; ++x)
            if (std::isfinite(row[x]) && row[x] > 0.0f)
                valid.push_back(row[x]);
    }
    check.validPixels = valid.size();
    if (valid.empty())
        return check;
    const auto middle = valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2);
    std::nth_element(valid.begin(), middle, valid.end());
    check.medianM = *middle;
    const bool tooNear = check.medianM < kNearestPlausibleMedianM;
    const bool tooFar = check.medianM > kFarthestPlausibleMedianM;
    if (!tooNear && !tooFar)
        return check;

    // The scales sensors and datasets write (README, "Depth scales"): the one that puts the
    // median nearest to a room's 2 m, among those that put it in range.
    const double units = check.medianM * unitsPerMetre;
    double bestDistance = 1e9;
    for (const double scale : {1000.0, 5000.0, 10000.0, 100.0}) {
        const double median = units / scale;
        if (scale == unitsPerMetre || median < kNearestPlausibleMedianM || median > kFarthestPlausibleMedianM)
            continue;
        const double distance = std::abs(std::log(median / 2.0));
        if (distance < bestDistance) {
            bestDistance = distance;
            check.suggestedScale = scale;
        }
    }
    const std::string fix =
        check.suggestedScale
            ? fmt::format("; if its 16-bit depth is in {}, add --depth-scale {:g} (median {:.2f} m)",
                          *check.suggestedScale == 1000.0 ? "millimetres" : fmt::format("units of 1/{:g} m", *check.suggestedScale),
                          *check.suggestedScale, units / *check.suggestedScale)
            : std::string("; check --depth-scale (units per metre of 16-bit depth)");
    check.warning = fmt::format("depth of {}: median {:.2f} m at {:g} units per metre, {} than depth sensors measure{}",
                                where, check.medianM, unitsPerMetre, tooNear ? "nearer" : "farther", fix);
    return check;
}

} // namespace defocus
