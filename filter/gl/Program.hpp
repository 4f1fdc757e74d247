// SPDX-License-Identifier: LGPL-2.1-or-later
// A linked GLSL program made from embedded shader files, with `#include "x.glsl"` resolved from
// the embedded set and variants chosen by a `#define` preamble.
#pragma once

#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "filter/gl/Objects.hpp"

namespace defocus::gl {

/// Thrown when a shader is missing, fails to compile or to link; carries the trimmed driver log.
class ShaderError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

class Program {
public:
    Program() = default;
    /// Builds `vertexFile` + `fragmentFile` (names in shaders/), with `defines` such as
    /// "SAMPLE_COUNT 16" inserted after the #version line. Throws ShaderError.
    Program(std::string_view vertexFile, std::string_view fragmentFile, std::string_view name,
            const std::vector<std::string>& defines = {});

    /// Builds the compute shader `computeFile` (a name in shaders/), as above.
    static Program compute(std::string_view computeFile, std::string_view name,
                           const std::vector<std::string>& defines = {});

    GLuint id() const { return handle_.id(); }
    void use() const { glUseProgram(id()); }
    /// Location of a uniform; -1 when the driver optimised it away.
    GLint uniform(const char* name) const { return glGetUniformLocation(id(), name); }

private:
    /// Links the compiled `shaders` (and deletes them), labelled `name`; throws ShaderError.
    void link(std::initializer_list<GLuint> shaders, std::string_view name);

    Handle<deleteProgram> handle_;
};

/// The shader text after include expansion and define insertion (exposed for tests).
std::string preprocessShader(std::string_view file, const std::vector<std::string>& defines);

} // namespace defocus::gl
