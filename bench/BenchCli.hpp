// SPDX-License-Identifier: LGPL-2.1-or-later
// What the benchmark programs add to the command line every program shares (samples/CliOptions.hpp):
// they drive the filter's inside directly (its GL context, the pipeline, the other methods), so
// its own errors are theirs to map.
#pragma once

#include <exception>

#include "filter/gl/EglContext.hpp"
#include "filter/gl/Program.hpp"
#include "samples/CliOptions.hpp"

namespace defocus::bench {

/// cli::statusFor, and kExitUnavailable for the GL errors of the filter's own code (no EGL
/// display or GL 4.5 context, a shader the driver refuses): a retry elsewhere may work.
inline int statusFor(const std::exception& error)
{
    if (dynamic_cast<const gl::ContextError*>(&error) || dynamic_cast<const gl::ShaderError*>(&error))
        return kExitUnavailable;
    return cli::statusFor(error);
}

} // namespace defocus::bench
