// SPDX-License-Identifier: LGPL-2.1-or-later
// Shader preprocessing (includes, defines), compilation and linking with readable errors.
#include "filter/gl/Program.hpp"

#include <sstream>

#include <fmt/format.h>

#include "filter/gl/EmbeddedShaders.hpp"

namespace defocus::gl {

namespace {

std::string_view lookup(std::string_view file)
{
    const auto& shaders = embeddedShaders();
    const auto found = shaders.find(file);
    if (found == shaders.end())
        throw ShaderError(fmt::format("defocus::gl::Program: no embedded shader '{}'", file));
    return found->second;
}

std::string expandIncludes(std::string_view file, int depth)
{
    if (depth > 8)
        throw ShaderError(fmt::format("defocus::gl::Program: include nesting too deep at '{}'", file));
    std::istringstream in{std::string(lookup(file))};
    std::string out, line;
    while (std::getline(in, line)) {
        if (line.rfind("#include", 0) == 0) {
            const auto open = line.find('"');
            const auto close = line.rfind('"');
            if (open == std::string::npos || close <= open)
                throw ShaderError(fmt::format("defocus::gl::Program: bad #include in '{}': {}", file, line));
            out += expandIncludes(line.substr(open + 1, close - open - 1), depth + 1);
        } else {
            out += line;
            out += '\n';
        }
    }
    return out;
}

std::string trimmedLog(GLuint object, bool isProgram)
{
    GLint length = 0;
    if (isProgram)
        glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
    else
        glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(length > 0 ? length : 1), '\0');
    if (isProgram)
        glGetProgramInfoLog(object, length, nullptr, log.data());
    else
        glGetShaderInfoLog(object, length, nullptr, log.data());
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n' || log.back() == ' '))
        log.pop_back();
    return log;
}

GLuint compile(GLenum stage, std::string_view file, const std::vector<std::string>& defines)
{
    const std::string source = preprocessShader(file, defines);
    const GLuint shader = glCreateShader(stage);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
        const std::string log = trimmedLog(shader, false);
        glDeleteShader(shader);
        throw ShaderError(fmt::format("defocus::gl::Program: '{}' does not compile:\n{}", file, log));
    }
    return shader;
}

} // namespace

std::string preprocessShader(std::string_view file, const std::vector<std::string>& defines)
{
    std::string text = expandIncludes(file, 0);
    if (text.rfind("#version", 0) != 0)
        throw ShaderError(fmt::format("defocus::gl::Program: '{}' must start with #version", file));
    std::string preamble;
    for (const auto& define : defines)
        preamble += "#define " + define + "\n";
    const auto endOfVersion = text.find('\n') + 1;
    text.insert(endOfVersion, preamble);
    return text;
}

Program::Program(std::string_view vertexFile, std::string_view fragmentFile, std::string_view name,
                 const std::vector<std::string>& defines)
{
    const GLuint vertex = compile(GL_VERTEX_SHADER, vertexFile, defines);
    GLuint fragment = 0;
    try {
        fragment = compile(GL_FRAGMENT_SHADER, fragmentFile, defines);
    } catch (...) {
        glDeleteShader(vertex);
        throw;
    }
    link({vertex, fragment}, name);
}

Program Program::compute(std::string_view computeFile, std::string_view name, const std::vector<std::string>& defines)
{
    Program program;
    program.link({compile(GL_COMPUTE_SHADER, computeFile, defines)}, name);
    return program;
}

void Program::link(std::initializer_list<GLuint> shaders, std::string_view name)
{
    const GLuint program = glCreateProgram();
    handle_ = Handle<deleteProgram>(program);
    for (const GLuint shader : shaders)
        glAttachShader(program, shader);
    glLinkProgram(program);
    for (const GLuint shader : shaders) {
        glDetachShader(program, shader);
        glDeleteShader(shader);
    }
    GLint ok = GL_FALSE;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (ok != GL_TRUE)
        throw ShaderError(fmt::format("defocus::gl::Program: '{}' does not link:\n{}", name, trimmedLog(program, true)));
    label(GL_PROGRAM, program, name);
}

} // namespace defocus::gl
