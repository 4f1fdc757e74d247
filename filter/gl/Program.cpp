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

GLuint compileSource(GLenum stage, std::string_view file, const std::string& source)
{
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

GLuint compile(GLenum stage, std::string_view file, const std::vector<std::string>& defines)
{
    return compileSource(stage, file, preprocessShader(file, defines));
}

// The compute main of computeFormSource(). COMPUTE_OUTPUTn name what the
// fragment shader declared (under its own #ifdefs, so a variant without an output has no define).
constexpr std::string_view kComputeMain = R"(
layout(local_size_x = 8, local_size_y = 8) in;
#ifdef COMPUTE_OUTPUT0
layout(binding = 0) writeonly uniform image2D uComputeOutput0;
#endif
#ifdef COMPUTE_OUTPUT1
layout(binding = 1) writeonly uniform image2D uComputeOutput1;
#endif
uniform uint uComputeSrgb;
#ifdef COMPUTE_TILES
layout(std140, binding = 1) uniform TileParams {
    vec2 targetSize;
    float tileSize;
    float tilePad;
};
layout(std430, binding = 7) readonly buffer ComputeTiles {
    ivec2 computeTiles[];
};
#endif

vec4 computeVec4(float v) { return vec4(v, 0.0, 0.0, 1.0); }
vec4 computeVec4(vec2 v) { return vec4(v, 0.0, 1.0); }
vec4 computeVec4(vec3 v) { return vec4(v, 1.0); }
vec4 computeVec4(vec4 v) { return v; }

// What an sRGB attachment's write does (the GL spec's encoding), for a store into its bytes.
vec4 computeEncode(vec4 v, uint index)
{
    if ((uComputeSrgb & (1u << index)) == 0u)
        return v;
    const vec3 c = clamp(v.rgb, 0.0, 1.0);
    const vec3 encoded = mix(1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, 12.92 * c, lessThan(c, vec3(0.0031308)));
    return vec4(encoded, v.a);
}

void main()
{
#ifdef COMPUTE_OUTPUT0
    const ivec2 size = imageSize(uComputeOutput0);
#else
    const ivec2 size = ivec2(0);
#endif
#ifdef COMPUTE_TILES
    const int tile = int(gl_WorkGroupID.y + gl_WorkGroupID.z * 65535u);
    if (tile >= computeTiles.length())
        return;
    const int side = int(tileSize);
    const int blocksPerRow = (side + 7) / 8;
    const ivec2 block = ivec2(int(gl_WorkGroupID.x) % blocksPerRow, int(gl_WorkGroupID.x) / blocksPerRow);
    const ivec2 inTile = block * 8 + ivec2(gl_LocalInvocationID.xy);
    if (inTile.x >= side || inTile.y >= side)
        return;
    const ivec2 pixel = computeTiles[tile] * side + inTile;
#else
    const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
#endif
    if (pixel.x >= size.x || pixel.y >= size.y)
        return;
    computeFragCoord = vec4(vec2(pixel) + 0.5, 0.0, 1.0);
    fragmentMain();
#ifdef COMPUTE_OUTPUT0
    imageStore(uComputeOutput0, pixel, computeEncode(computeVec4(COMPUTE_OUTPUT0), 0u));
#endif
#ifdef COMPUTE_OUTPUT1
    imageStore(uComputeOutput1, pixel, computeEncode(computeVec4(COMPUTE_OUTPUT1), 1u));
#endif
}
)";

} // namespace

std::string computeFormSource(std::string_view fragmentFile, const std::vector<std::string>& defines, bool tiles)
{
    std::vector<std::string> all = defines;
    all.emplace_back("COMPUTE_FORM 1");
    if (tiles)
        all.emplace_back("COMPUTE_TILES 1");
    const std::string text = preprocessShader(fragmentFile, all);
    std::istringstream in(text);
    std::string out, line;
    bool first = true, sawMain = false;
    while (std::getline(in, line)) {
        // `layout(location = N) out T name;` (the pixel's position comes from gl_FragCoord,
        // never from an interpolated input); uniforms at a location stay as they are.
        const std::string_view layout = "layout(location = ";
        std::string direction, type, name, index;
        if (line.rfind(layout, 0) == 0) {
            const std::size_t close = line.find(')');
            index = line.substr(layout.size(), close - layout.size());
            std::istringstream rest(line.substr(close + 1));
            rest >> direction >> type >> name;
        }
        if (!direction.empty() && direction != "uniform") {
            if (name.empty() || name.back() != ';' || direction != "out" || (index != "0" && index != "1"))
                throw ShaderError(fmt::format("defocus::gl::Program: '{}' has an interface the compute form "
                                              "does not take: {}", fragmentFile, line));
            name.pop_back();
            out += fmt::format("{} {};\n#define COMPUTE_OUTPUT{} {}\n", type, name, index, name);
            continue;
        }
        if (line == "void main()") {
            out += "void fragmentMain()\n";
            sawMain = true;
            continue;
        }
        for (std::size_t at = line.find("gl_FragCoord"); at != std::string::npos; at = line.find("gl_FragCoord", at))
            line.replace(at, 12, "computeFragCoord");
        out += line;
        out += '\n';
        if (first) { // after #version
            out += "vec4 computeFragCoord;\n";
            first = false;
        }
    }
    if (!sawMain)
        throw ShaderError(fmt::format("defocus::gl::Program: '{}' has no 'void main()' line", fragmentFile));
    out += kComputeMain;
    return out;
}

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
    fragmentFile_ = fragmentFile;
    name_ = name;
    defines_ = defines;
    tiles_ = vertexFile == "tiles.vert";
}

const Program& Program::computeForm() const
{
    if (fragmentFile_.empty())
        throw ShaderError(fmt::format("defocus::gl::Program: '{}' has no fragment shader to run as a compute shader",
                                      name_));
    if (!computeForm_) {
        const std::string name = name_ + " (compute)";
        auto program = std::make_unique<Program>();
        program->link({compileSource(GL_COMPUTE_SHADER, fragmentFile_, computeFormSource(fragmentFile_, defines_, tiles_))},
                      name);
        program->computeSrgbLocation_ = program->uniform("uComputeSrgb");
        computeForm_ = std::move(program);
    }
    return *computeForm_;
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
