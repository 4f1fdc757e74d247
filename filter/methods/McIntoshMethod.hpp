// "mcintosh": the project's McIntosh hexagonal chain (defocus::Pipeline) as a registry entry, with
// QualitySettings taken from the method settings.
#pragma once

#include "filter/Pipeline.hpp"
#include "filter/methods/Method.hpp"

namespace defocus {

class McIntoshMethod final : public Method {
public:
    explicit McIntoshMethod(bool timers) : pipeline_(timers) {}
    const MethodInfo& info() const override;
    /// The QualitySettings the pipeline runs with: samples and precision from `settings`,
    /// adaptive tiles on (what users get).
    static QualitySettings quality(const MethodSettings& settings);

private:
    MethodResult process(const Frame& frame, const LensSettings& lens, const MethodSettings& settings) override;
    Pipeline pipeline_;
};

} // namespace defocus
