// SPDX-License-Identifier: LGPL-2.1-or-later
// Synthetic source: frames rendered on demand by SyntheticScene.
#include "sources/SyntheticSource.hpp"

#include <cmath>
#include <utility>

#include <fmt/format.h>

namespace defocus {

SyntheticSource::SyntheticSource(SceneDescription scene, SyntheticSettings settings)
    : scene_(std::move(scene), settings)
{
}

std::optional<Frame> SyntheticSource::next()
{
    if (next_ >= scene_.settings().frames)
        return std::nullopt;
    return scene_.render(next_++, false).frame;
}

std::string SyntheticSource::describe() const
{
    const SyntheticSettings& s = scene_.settings();
    const std::string focus = s.focusPull ? fmt::format("focus pull {:.1f} -> {:.1f} m", scene_.description().focusFromM,
                                                        scene_.description().focusToM)
                                          : fmt::format("focus {:.2f} m", s.lens.focusM);
    return fmt::format("synthetic scene '{}' ({} frames {}x{}, {} mm f/{:g}, {}, {} triangles)", scene_.description().name,
                       s.frames, s.width, s.height, s.lens.focalLengthMm, s.lens.fNumber, focus,
                       scene_.triangleCount());
}

} // namespace defocus
