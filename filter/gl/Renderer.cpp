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

namespace {

/// The choice `variable` makes: `onValue` true, `offValue` false, unset the renderer's default
/// (a GPU's: true); another value is warned about and ignored.
bool chosen(const char* variable, std::string_view onValue, std::string_view offValue, std::string_view glRenderer)
{
    const char* set = std::getenv(variable);
    const std::string_view value = set ? set : "";
    if (value == onValue || value == offValue)
        return value == onValue;
    if (!value.empty())
        logger().warn("{}='{}' is neither '{}' nor '{}': ignored", variable, value, onValue, offValue);
    return !isSoftwareRenderer(glRenderer);
}

} // namespace

bool depthPrepOnGpu(std::string_view glRenderer)
{
    return chosen("DEFOCUS_DEPTH_PREP", "gpu", "cpu", glRenderer);
}

bool computePasses(std::string_view glRenderer)
{
    return chosen("DEFOCUS_PASSES", "compute", "fragment", glRenderer);
}

} // namespace defocus::gl
