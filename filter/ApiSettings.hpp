// SPDX-License-Identifier: LGPL-2.1-or-later
// The public settings (include/defocus/Settings.hpp: Lens, Quality) as the pipeline's own
// (filter/Settings.hpp: LensSettings, QualitySettings), for libdefocus and for the programs that
// parse the public words but drive the pipeline directly (the preview, the bench). Internal: not
// part of the API.
#pragma once

#include <optional>
#include <string_view>

#include "defocus/Settings.hpp"
#include "filter/Settings.hpp"

namespace defocus {

/// "fast", "balanced", "high".
std::string_view presetName(Quality::Preset preset);
/// The preset called `name` ("fast", "balanced", "high"); nullopt for another name.
std::optional<Quality::Preset> parsePreset(std::string_view name);

/// The lens as the pipeline knows it.
LensSettings toLens(const Lens& lens);
/// The numbers of `in` back into `lens` (its model and field of view are kept).
void fromLens(const LensSettings& in, Lens& lens);

/// The pipeline's view for a public one (Settings::View lists them in kAllViews' order).
View toView(Settings::View view);
/// The public view called `name` as viewName() prints it ("composite", ...); nullopt for another.
std::optional<Settings::View> parseApiView(std::string_view name);

/// The preset's samples, precision, kernel, near field and resolution unless set, as the
/// command line fills what its flags leave out; every other field as given.
QualitySettings toQuality(const Quality& quality);
/// `quality` with every field left empty set to its preset's value (defocus::resolve).
Quality resolveQuality(const Quality& quality);

} // namespace defocus
