// SPDX-License-Identifier: LGPL-2.1-or-later
// The public settings as the pipeline's: filter/ApiSettings.hpp.
#include "filter/ApiSettings.hpp"

#include <iterator>

#include "filter/Presets.hpp"

namespace defocus {

std::string_view presetName(Quality::Preset preset)
{
    switch (preset) {
    case Quality::Preset::Fast: return "fast";
    case Quality::Preset::High: return "high";
    default: return "balanced";
    }
}

std::optional<Quality::Preset> parsePreset(std::string_view name)
{
    for (const auto preset : {Quality::Preset::Fast, Quality::Preset::Balanced, Quality::Preset::High})
        if (presetName(preset) == name)
            return preset;
    return std::nullopt;
}

View toView(Settings::View view)
{
    return kAllViews[static_cast<int>(view)];
}

std::optional<Settings::View> parseApiView(std::string_view name)
{
    View view = View::Composite;
    if (!parseView(name, view))
        return std::nullopt;
    for (int v = 0; v < static_cast<int>(std::size(kAllViews)); ++v)
        if (kAllViews[v] == view)
            return static_cast<Settings::View>(v);
    return std::nullopt;
}

LensSettings toLens(const Lens& lens)
{
    LensSettings out;
    out.model = lens.cocModel == Lens::Model::FocalRange ? CocModel::FocalRange : CocModel::ThinLens;
    out.focalLengthMm = lens.focalLengthMm;
    out.fNumber = lens.fNumber;
    out.focusM = lens.focusM;
    out.sensorWidthMm = lens.sensorWidthMm;
    out.fieldOfView = lens.fovFrom == Lens::FovFrom::FocalLength ? FieldOfView::FocalLength : FieldOfView::ImageDistance;
    out.maxCocPx = lens.maxCocPx;
    out.blades = lens.blades;
    out.bladeRotationDeg = lens.bladeRotationDeg;
    out.apertureRatio = lens.apertureRatio;
    out.nearLimitM = lens.nearM;
    out.farLimitM = lens.farM;
    return out;
}

void fromLens(const LensSettings& in, Lens& lens)
{
    lens.focalLengthMm = in.focalLengthMm;
    lens.fNumber = in.fNumber;
    lens.focusM = in.focusM;
    lens.sensorWidthMm = in.sensorWidthMm;
    lens.maxCocPx = in.maxCocPx;
    lens.blades = in.blades;
    lens.bladeRotationDeg = in.bladeRotationDeg;
    lens.apertureRatio = in.apertureRatio;
    lens.nearM = in.nearLimitM;
    lens.farM = in.farLimitM;
}

QualitySettings toQuality(const Quality& quality)
{
    const QualitySettings preset = presetSettings(presetName(quality.preset));
    QualitySettings out;
    out.samples = quality.samples.value_or(preset.samples);
    out.targetFormat = quality.precision ? (*quality.precision == Quality::Precision::F32 ? TargetFormat::Rgba32F
                                                                                          : TargetFormat::Rgba16F)
                                         : preset.targetFormat;
    out.kernel = quality.hexagon ? (*quality.hexagon == Quality::Hexagon::McIntosh ? HexagonKernel::McIntoshMin
                                                                                   : HexagonKernel::RhombiSum)
                                 : preset.kernel;
    out.nearField = quality.nearField.value_or(preset.nearField);
    out.resolution = quality.resolution ? (*quality.resolution == Quality::Resolution::Half ? Resolution::Half
                                                                                            : Resolution::Full)
                                        : preset.resolution;
    out.highlightSprites = quality.highlightSprites;
    out.highlightGain = quality.highlightGain;
    out.adaptive = !quality.alwaysOn;
    return out;
}

Quality resolveQuality(const Quality& quality)
{
    const QualitySettings q = toQuality(quality);
    Quality out = quality;
    out.samples = q.samples;
    out.hexagon = q.kernel == HexagonKernel::McIntoshMin ? Quality::Hexagon::McIntosh : Quality::Hexagon::Rhombi;
    // The preset's own precision is the renderer's: it stays unset.
    if (q.targetFormat == TargetFormat::Auto)
        out.precision.reset();
    else
        out.precision = q.targetFormat == TargetFormat::Rgba32F ? Quality::Precision::F32 : Quality::Precision::F16;
    out.resolution = q.resolution == Resolution::Half ? Quality::Resolution::Half : Quality::Resolution::Full;
    out.nearField = q.nearField;
    return out;
}

} // namespace defocus
