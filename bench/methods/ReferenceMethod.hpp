// SPDX-License-Identifier: LGPL-2.1-or-later
// "reference" and "reference-pointy": the CPU scatter (ReferenceScatter.hpp) as registry entries,
// with the filter's CoC model and input conventions.
#pragma once

#include "bench/methods/Method.hpp"
#include "bench/methods/ReferenceScatter.hpp"

namespace defocus {

class ReferenceMethod final : public Method {
public:
    /// `name`: "reference" (hexagon with flat top and bottom, the McIntosh chain's) or
    /// "reference-pointy" (a corner on top, what Blender Cycles renders for blade rotation 0).
    explicit ReferenceMethod(std::string_view name);
    const MethodInfo& info() const override { return *info_; }

private:
    MethodResult process(const Frame& frame, const LensSettings& lens, const MethodSettings& settings) override;
    const MethodInfo* info_;
    ScatterOptions options_;
};

} // namespace defocus
