// SPDX-License-Identifier: LGPL-2.1-or-later
// The renderer's kind and the choices made from it.
#include "filter/gl/Renderer.hpp"

#include <cstdlib>

#include "filter/Log.hpp"

namespace defocus::gl {

bool isSoftwareRenderer(std::string_view glRenderer)
{
    return glRenderer.starts_with("llvmpipe") || glRenderer.starts_with("softpipe") ||
           glRenderer.find("Software Rasterizer") != std::string_view::npos;
}

bool depthPrepOnGpu(std::string_view glRenderer)
{
    const char* chosen = std::getenv("DEFOCUS_DEPTH_PREP");
    const std::string_view value = chosen ? chosen : "";
    if (value == "gpu" || value == "cpu")
        return value == "gpu";
    if (!value.empty())
        logger().warn("DEFOCUS_DEPTH_PREP='{}' is neither 'gpu' nor 'cpu': ignored", value);
    return !isSoftwareRenderer(glRenderer);
}

} // namespace defocus::gl
