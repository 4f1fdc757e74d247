// SPDX-License-Identifier: LGPL-2.1-or-later
// The GLSL sources from shaders/, compiled into the binary by cmake/EmbedShaders.cmake.
#pragma once

#include <map>
#include <string_view>

namespace defocus::gl {

/// File name (e.g. "hex_blur.frag") -> source text.
const std::map<std::string_view, std::string_view>& embeddedShaders();

} // namespace defocus::gl
