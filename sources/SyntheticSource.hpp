// SPDX-License-Identifier: LGPL-2.1-or-later
// A FrameSource that renders a synthetic scene frame by frame: the filter's input with no data
// on disk, and, through scene(), the thin-lens reference of the same frame.
//   defocus --demo -o out.mp4                       (60 frames of "spheres", focus pull)
//   defocus --demo --demo-scene edges -o out/ --f-number 1.4
#pragma once

#include "sources/FrameSource.hpp"
#include "sources/SyntheticScene.hpp"

namespace defocus {

class SyntheticSource : public FrameSource {
public:
    /// Needs a current OpenGL 4.5 context, as SyntheticScene does; throws what it throws.
    SyntheticSource(SceneDescription scene, SyntheticSettings settings);

    /// Colour and depth of the next frame (no reference: that costs aperture.samples renders).
    std::optional<Frame> next() override;
    std::optional<std::size_t> frameCount() const override { return scene_.settings().frames; }
    double frameRate() const override { return scene_.settings().frameRate; }
    std::string describe() const override;

    /// The lens of frame `index`, focus pull included: what the filter must use for that frame.
    LensSettings lensAt(std::size_t index) const { return scene_.lensAt(index); }
    /// The renderer, e.g. for scene().render(index) with the reference.
    SyntheticScene& scene() { return scene_; }

private:
    SyntheticScene scene_;
    std::size_t next_ = 0;
};

} // namespace defocus
