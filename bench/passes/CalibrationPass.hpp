// SPDX-License-Identifier: LGPL-2.1-or-later
// A fixed reference workload for timing regressions. Shader: calibration.frag.
#pragma once

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

class CalibrationPass {
public:
    static constexpr const char* kName = "calibration";
    CalibrationPass();
    void run(const gl::Texture& source, const gl::Framebuffer& target);

private:
    gl::Program program_;
    gl::Sampler linear_;
};

} // namespace defocus
