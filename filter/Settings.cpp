// SPDX-License-Identifier: LGPL-2.1-or-later
// The one place where settings are checked against their documented ranges.
#include "filter/Settings.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

namespace defocus {

namespace {

/// Sets `value` to the one of `values` whose name (`nameOf`) is `name`; false when none is.
template <typename Enum, typename Values, typename NameOf>
bool parseName(std::string_view name, const Values& values, NameOf nameOf, Enum& value)
{
    for (const Enum candidate : values)
        if (nameOf(candidate) == name) {
            value = candidate;
            return true;
        }
    return false;
}

constexpr std::string_view kViewNames[] = {"input", "horizontal", "diagonal-a", "diagonal-b",
                                           "composite", "depth", "coc"};

template <typename T>
void checkRange(std::vector<SettingIssue>& issues, std::string_view parameter, T& value, T low, T high,
                bool clamp)
{
    if (std::isfinite(static_cast<double>(value)) && value >= low && value <= high)
        return;
    issues.push_back({std::string(parameter), fmt::format("{} must be between {} and {}, not {}", parameter, low, high, value)});
    if (clamp)
        value = std::isnan(static_cast<double>(value)) ? low : std::clamp(value, low, high);
}

} // namespace

std::string_view viewName(View view)
{
    return kViewNames[static_cast<int>(view)];
}

bool parseView(std::string_view name, View& view)
{
    return parseName(name, kAllViews, [](View v) { return viewName(v); }, view);
}

std::vector<SettingIssue> validate(LensSettings& lens, bool clamp)
{
    std::vector<SettingIssue> issues;
    checkRange(issues, "--focal-length", lens.focalLengthMm, limits::kFocalLengthMm[0], limits::kFocalLengthMm[1], clamp);
    checkRange(issues, "--f-number", lens.fNumber, limits::kFNumber[0], limits::kFNumber[1], clamp);
    checkRange(issues, "--sensor-width", lens.sensorWidthMm, limits::kSensorWidthMm[0], limits::kSensorWidthMm[1], clamp);
    checkRange(issues, "--max-coc", lens.maxCocPx, limits::kMaxCocPx[0], limits::kMaxCocPx[1], clamp);
    checkRange(issues, "--blade-rotation", lens.bladeRotationDeg, limits::kBladeRotationDeg[0],
               limits::kBladeRotationDeg[1], clamp);
    checkRange(issues, "--aperture-ratio", lens.apertureRatio, limits::kApertureRatio[0], limits::kApertureRatio[1],
               clamp);
    if (lens.blades != 0 && (lens.blades < limits::kBlades[0] || lens.blades > limits::kBlades[1])) {
        issues.push_back({"--blades", fmt::format("--blades must be 0 (circular) or between {} and {}, not {}",
                                                  limits::kBlades[0], limits::kBlades[1], lens.blades)});
        if (clamp)
            lens.blades = std::clamp(lens.blades, limits::kBlades[0], limits::kBlades[1]);
    }

    // The thin lens only images points beyond its focal length: focus must be farther than f.
    const double focalLengthM = lens.focalLengthMm * 1e-3;
    if (std::isnan(lens.focusM) || lens.focusM <= focalLengthM) {
        issues.push_back({"--focus", fmt::format("--focus {} m must be farther than the focal length ({} m)",
                                                 lens.focusM, focalLengthM)});
        if (clamp)
            lens.focusM = std::isnan(lens.focusM) ? 2.0 : focalLengthM * 1.01;
    }
    if (lens.model == CocModel::FocalRange) {
        if (!(lens.nearLimitM >= 0.0 && lens.nearLimitM < lens.focusM)) {
            issues.push_back({"--near", fmt::format("--near {} m must be in [0, focus {} m)", lens.nearLimitM, lens.focusM)});
            if (clamp)
                // Just in front of the focus; with the focus at infinity, the largest finite distance.
                lens.nearLimitM = std::isnan(lens.nearLimitM)
                                      ? 0.0
                                      : std::clamp(lens.nearLimitM, 0.0,
                                                   std::isinf(lens.focusM) ? std::numeric_limits<double>::max()
                                                                           : lens.focusM * 0.99);
        }
        // +inf is the closed end of (focus, +inf], so it stays allowed when the focus is at infinity.
        if (!(lens.farLimitM > lens.focusM || lens.farLimitM == std::numeric_limits<double>::infinity())) {
            issues.push_back({"--far", fmt::format("--far {} m must be farther than focus {} m", lens.farLimitM, lens.focusM)});
            if (clamp)
                lens.farLimitM = lens.focusM * 1.01;
        }
    }
    return issues;
}

std::vector<SettingIssue> validate(QualitySettings& quality, bool clamp)
{
    std::vector<SettingIssue> issues;
    checkRange(issues, "--samples", quality.samples, limits::kSamples[0], limits::kSamples[1], clamp);
    checkRange(issues, "--highlight-gain", quality.highlightGain, limits::kHighlightGain[0], limits::kHighlightGain[1],
               clamp);
    return issues;
}

std::string_view fieldOfViewName(FieldOfView fov)
{
    return fov == FieldOfView::ImageDistance ? "image-distance" : "focal-length";
}

bool parseFieldOfView(std::string_view name, FieldOfView& fov)
{
    constexpr FieldOfView kAll[] = {FieldOfView::ImageDistance, FieldOfView::FocalLength};
    return parseName(name, kAll, fieldOfViewName, fov);
}

std::string_view resolutionName(Resolution resolution)
{
    return resolution == Resolution::Full ? "full" : "half";
}

bool parseResolution(std::string_view name, Resolution& resolution)
{
    constexpr Resolution kAll[] = {Resolution::Full, Resolution::Half};
    return parseName(name, kAll, resolutionName, resolution);
}

std::string_view kernelName(HexagonKernel kernel)
{
    return kernel == HexagonKernel::McIntoshMin ? "mcintosh" : "rhombi";
}

bool parseKernel(std::string_view name, HexagonKernel& kernel)
{
    constexpr HexagonKernel kAll[] = {HexagonKernel::McIntoshMin, HexagonKernel::RhombiSum};
    return parseName(name, kAll, kernelName, kernel);
}

bool parseFocus(std::string_view text, LensSettings& lens, bool& isAuto)
{
    isAuto = text == "auto";
    if (isAuto)
        return true;
    if (text == "inf" || text == "infinity") {
        lens.focusM = std::numeric_limits<double>::infinity();
        return true;
    }
    try {
        const std::string value(text);
        std::size_t used = 0;
        const double metres = std::stod(value, &used);
        if (used != value.size())
            return false;
        lens.focusM = metres;
        return true;
    } catch (const std::logic_error&) {
        return false;
    }
}

std::vector<SettingIssue> validateCommandLine(const LensSettings& lens, QualitySettings quality, bool autoFocus)
{
    LensSettings checked = lens;
    if (autoFocus)
        checked.focusM = std::max(checked.focusM, checked.focalLengthMm * 2e-3);
    auto issues = validate(checked);
    const auto qualityIssues = validate(quality);
    issues.insert(issues.end(), qualityIssues.begin(), qualityIssues.end());
    return issues;
}

} // namespace defocus
