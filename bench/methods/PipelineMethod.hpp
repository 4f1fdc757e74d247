// SPDX-License-Identifier: LGPL-2.1-or-later
// The filter's own chains (defocus::Pipeline) as registry entries: "mcintosh" (McIntosh et al.
// 2012, min() of two rhombi), "rhombi" (three one-sided rhombi summed), each also with its
// foreground handling ("-near"). QualitySettings come from the method name and settings.
#pragma once

#include <string_view>

#include "bench/methods/Method.hpp"
#include "filter/Pipeline.hpp"

namespace defocus {

class PipelineMethod final : public Method {
public:
    /// `name`: mcintosh, mcintosh-near, rhombi or rhombi-near.
    PipelineMethod(std::string_view name, bool timers);
    const MethodInfo& info() const override { return info_; }
    /// The QualitySettings the pipeline runs with for method `name`: kernel and near field from
    /// the name, samples, resolution, precision and the plan (on by default, what users get)
    /// from `settings`.
    /// Throws std::invalid_argument for a name that is not one of the four.
    static QualitySettings quality(std::string_view name, const MethodSettings& settings);
    static bool handles(std::string_view name);

private:
    bool scalesItself() const override { return true; }
    MethodResult process(const Frame& frame, const LensSettings& lens, const MethodSettings& settings) override;
    const MethodInfo& info_;
    Pipeline pipeline_;
};

} // namespace defocus
