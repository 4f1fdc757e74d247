// SPDX-License-Identifier: LGPL-2.1-or-later
// What kind of renderer a GL_RENDERER string names: the choices that depend on it (where depth
// prep runs, the presets' precision) are made from this one test.
#pragma once

#include <string_view>

namespace defocus::gl {

/// Mesa's software renderers (llvmpipe, softpipe, the classic swrast), which run the GPU's work
/// on the CPU.
inline bool isSoftwareRenderer(std::string_view glRenderer)
{
    return glRenderer.starts_with("llvmpipe") || glRenderer.starts_with("softpipe") ||
           glRenderer.find("Software Rasterizer") != std::string_view::npos;
}

} // namespace defocus::gl
