// SPDX-License-Identifier: LGPL-2.1-or-later
// A linked GLSL program made from embedded shader files, with `#include "x.glsl"` resolved from
// the embedded set and variants chosen by a `#define` preamble.
#pragma once

#include <initializer_list>
#include <memory>
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

    /// A program built from a fragment shader, as a compute shader over the same pixels
    /// (computeFormSource()), built on first use and kept; its uniform uComputeSrgb says which
    /// outputs to encode as sRGB. Throws ShaderError (and for a compute program).
    const Program& computeForm() const;
    /// A compute form's uComputeSrgb, looked up once when it was built (-1 elsewhere).
    GLint computeSrgbLocation() const { return computeSrgbLocation_; }

private:
    /// Links the compiled `shaders` (and deletes them), labelled `name`; throws ShaderError.
    void link(std::initializer_list<GLuint> shaders, std::string_view name);

    Handle<deleteProgram> handle_;
    /// What computeForm() builds from: the fragment shader, its defines, whether it was drawn
    /// on tiles (tiles.vert), the name.
    std::string fragmentFile_, name_;
    std::vector<std::string> defines_;
    bool tiles_ = false;
    GLint computeSrgbLocation_ = -1;
    mutable std::unique_ptr<Program> computeForm_;
};

/// The shader text after include expansion and define insertion (exposed for tests).
std::string preprocessShader(std::string_view file, const std::vector<std::string>& defines);

/// A fragment shader made into a compute shader of 8x8 work groups, one invocation a pixel: its
/// `main` becomes a function the compute `main` calls for each pixel of image unit 0's size, with
/// `gl_FragCoord` at the pixel's centre; each `layout(location = N) out` (N = 0, 1) becomes a
/// variable stored afterwards into the image on unit N, encoded as sRGB where bit N of the uniform
/// uComputeSrgb is set. A shader with inputs (an interpolated uv) is refused: ShaderError. `tiles`: the
/// pixels of the tiles in TileList's storage buffer (binding 7, with tiles.vert's TileParams),
/// as tiles.vert draws them; one work group per 8x8 block of a tile, tile k's in row
/// k mod 65535 and layer k / 65535 of the dispatch (TileList::dispatch()).
std::string computeFormSource(std::string_view fragmentFile, const std::vector<std::string>& defines, bool tiles);

} // namespace defocus::gl
