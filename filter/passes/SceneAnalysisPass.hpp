// Scene analysis on the GPU: a compute pass over the uploaded depth and colour measures what the
// frame calls for (SceneMeasurement) and reads it back for the plan. Shader: scene_analysis.comp.
#pragma once

#include <opencv2/core.hpp>

#include "filter/Lens.hpp"
#include "filter/SceneAnalysis.hpp"
#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class SceneAnalysisPass {
public:
    static constexpr const char* kName = "analysis";
    SceneAnalysisPass();
    /// `depth`: R32F metres with no holes; `color`: sRGB8 (`eightBit`) or float RGB, the same
    /// size. Waits for the result: the plan needs it before the blur passes are recorded.
    SceneMeasurement run(const gl::Texture& depth, const gl::Texture& color, bool eightBit, const CocCoefficients& k);
    /// The last run's measurement as the GPU holds it (scene_analysis.comp's layout), for the
    /// bokeh sprites' comparison of a pixel with its tile (highlights.glsl).
    const gl::StorageBuffer& measurement() const { return measurement_; }

private:
    gl::Program program_, eightBitProgram_;
    gl::UniformBuffer uniforms_; ///< CocParams (coc_params.glsl)
    gl::StorageBuffer measurement_;
    gl::Sampler nearest_;
};

} // namespace defocus
