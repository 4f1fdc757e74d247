// SPDX-License-Identifier: LGPL-2.1-or-later
// The scene measurement on the GPU: per 16x16 tile the depth range, the highlight pixels and the
// summed luminance, and the frame's |CoC| histogram, from the filled depth and the colour as the
// CoC pass samples them; what measureScene() measures on the CPU (filter/SceneAnalysis.hpp).
// Only the measurement comes back (16 bytes a tile), for the plan, through a fenced buffer. Shader: scene_measure.comp.
#pragma once

#include <cstddef>

#include <opencv2/core.hpp>

#include "filter/SceneAnalysis.hpp"
#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"
#include "filter/passes/CocParams.hpp"

namespace defocus {

class SceneMeasurePass {
public:
    static constexpr const char* kName = "scene-measure";
    SceneMeasurePass();

    /// Measures `depth` (R32F metres, filled) and `color`, both of the frame's size, with the
    /// CoC of `params` (the frame's; its coefficients are all this reads): `color` is float linear, or with `eightBit` the frame's sRGB bytes undecoded
    /// (GL_RGB8, a view of the CoC pass's sRGB8 texture: Texture::view()). `measured`:
    /// DepthPrepPass::measured(), whose holes are counted; nullptr for a frame without depth.
    /// The measurement goes to `out`, made large enough, and is queued to come back in `back`
    /// (made large enough) behind a fence; read() takes it from there.
    void run(const gl::Texture& depth, const gl::Texture& color, bool eightBit, const CocParams& params,
             const gl::Texture* measured, gl::StorageBuffer& out, gl::ReadbackBuffer& back);
    /// Waits for the measurement run() queued to `back` (for the GPU to get that far, not for
    /// what was queued after it), of a frame of `frame` pixels, and returns it, with the pixels
    /// of the depth that had no measurement in `invalidPixels` (all of them where `countedHoles`
    /// is false: the frame had no depth).
    static SceneMeasurement read(gl::ReadbackBuffer& back, cv::Size frame, bool countedHoles,
                                 std::size_t& invalidPixels);

private:
    gl::Program program_;
    GLint eightBitLocation_ = -1, countHolesLocation_ = -1;
    gl::Sampler nearest_;
};

} // namespace defocus
