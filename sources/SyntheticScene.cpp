// SPDX-License-Identifier: LGPL-2.1-or-later
// Synthetic scenes rasterised with GL: the pinhole colour and planar depth the filter takes, and a
// thin-lens reference accumulated over renders from points of a polygonal aperture through
// sheared frusta that keep the focus plane fixed (P. Haeberli and K. Akeley, "The Accumulation
// Buffer: Hardware Support for High-Quality Rendering", SIGGRAPH 1990).
#include "sources/SyntheticScene.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <utility>

#include <epoxy/gl.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <opencv2/imgproc.hpp>

#include "filter/gl/Objects.hpp"
#include "filter/gl/Program.hpp"

namespace defocus {

namespace {

constexpr double kPi = std::numbers::pi;

/// Clip planes of every render, metres: nearer than anything the scenes put before the lens, and
/// beyond their farthest wall. The depth buffer is 32-bit float, so the ratio costs nothing.
constexpr float kNearM = 0.05f;
constexpr float kFarM = 1000.0f;

/// Radical inverse in base 2 (van der Corput), the second coordinate of a Hammersley set.
double radicalInverse2(std::uint32_t i)
{
    i = (i << 16u) | (i >> 16u);
    i = ((i & 0x55555555u) << 1u) | ((i & 0xAAAAAAAAu) >> 1u);
    i = ((i & 0x33333333u) << 2u) | ((i & 0xCCCCCCCCu) >> 2u);
    i = ((i & 0x0F0F0F0Fu) << 4u) | ((i & 0xF0F0F0F0u) >> 4u);
    i = ((i & 0x00FF00FFu) << 8u) | ((i & 0xFF00FF00u) >> 8u);
    return static_cast<double>(i) * (1.0 / 4294967296.0);
}

/// The n-point Hammersley set ((i + 1/2) / n, radical inverse of i): a (0, m, 2)-net for n = 2^m,
/// stratified for every n.
glm::dvec2 hammersley(int i, int n)
{
    return {(i + 0.5) / n, radicalInverse2(static_cast<std::uint32_t>(i))};
}

/// A fixed permutation of 0..n-1 (Fisher-Yates driven by a 64-bit LCG, so it is the same on
/// every standard library). It pairs the reference's pixel offsets with its lens positions in
/// an order unrelated to both, so that the two 2D sets do not correlate.
std::vector<int> permutation(int n)
{
    std::vector<int> p(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
        p[static_cast<std::size_t>(i)] = i;
    std::uint64_t state = 0x9E3779B97F4A7C15ull;
    for (int i = n - 1; i > 0; --i) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        const int j = static_cast<int>((state >> 33) % static_cast<std::uint64_t>(i + 1));
        std::swap(p[static_cast<std::size_t>(i)], p[static_cast<std::size_t>(j)]);
    }
    return p;
}

double smoothstep(double t)
{
    t = std::clamp(t, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// ---- geometry ---------------------------------------------------------------------------------

/// One vertex as the vertex shader reads it: world position and normal, pattern coordinates in
/// metres along the surface, material index.
struct Vertex {
    glm::vec3 position;
    glm::vec3 normal;
    glm::vec2 uv;
    std::uint32_t material;
};

/// std430 mirror of `Material` in shaders/synthetic_scene.frag.
struct MaterialBlock {
    glm::vec4 colorAPattern; ///< rgb albedo or light colour, a = Pattern as a number
    glm::vec4 colorBScale;   ///< rgb second albedo, a = pattern period in metres
    glm::vec4 emission;      ///< x = emission multiplier (0 = lit surface)
};

/// std140 mirror of the `Camera` block in shaders/synthetic_scene.vert.
struct CameraBlock {
    glm::mat4 viewProjection; ///< this render's eye: sheared, jittered
    glm::mat4 view;           ///< the lens centre's world -> camera transform (planar depth)
};

class MeshBuilder {
public:
    void addBox(const SceneObject& object, std::uint32_t material)
    {
        const glm::mat3 yaw = yawMatrix(object.yawDeg);
        const glm::vec3 h = object.halfSize;
        // For each face axis, the two in-face axes its pattern coordinates run along: walls
        // facing the camera (z) get (x, y), side faces (z, y), top and bottom (x, z).
        static constexpr int kTangents[3][2] = {{2, 1}, {0, 2}, {0, 1}};
        for (int axis = 0; axis < 3; ++axis)
            for (const float sign : {-1.0f, 1.0f}) {
                const int b = kTangents[axis][0], c = kTangents[axis][1];
                glm::vec3 normal(0.0f);
                normal[axis] = sign;
                Vertex corners[4];
                int k = 0;
                for (const float sb : {-1.0f, 1.0f})
                    for (const float sc : {-1.0f, 1.0f}) {
                        glm::vec3 local(0.0f);
                        local[axis] = sign * h[axis];
                        local[b] = sb * h[b];
                        local[c] = sc * h[c];
                        corners[k++] = {object.centre + yaw * local, yaw * normal, {local[b], local[c]}, material};
                    }
                addTriangle(corners[0], corners[1], corners[3]);
                addTriangle(corners[0], corners[3], corners[2]);
            }
    }

    /// `eye`: where the shot starts, to size the tessellation to the sphere's image.
    void addSphere(const SceneObject& object, std::uint32_t material, glm::vec3 eye)
    {
        const float r = object.halfSize.x;
        // Enough segments that the polygonal silhouette is within half a pixel of the circle,
        // r (1 - cos(pi / n)) <= 1/2 for the image's radius r at 50 mm over 640 px (889 px per
        // unit of tangent), 8 to 32; vertices cost twice per render (depth and shading passes).
        const double radiusPx = 889.0 * r / std::max(glm::distance(object.centre, eye) - r, 0.1f);
        const double exact = kPi / std::acos(std::max(1.0 - 0.5 / radiusPx, -1.0));
        const int segments = 2 * std::clamp(static_cast<int>(std::ceil(exact / 2.0)), 4, 16);
        const int rings = segments / 2;
        std::vector<Vertex> grid;
        for (int j = 0; j <= rings; ++j) {
            const double theta = kPi * j / rings; // from the top
            for (int i = 0; i <= segments; ++i) {
                const double phi = 2.0 * kPi * i / segments;
                const glm::vec3 n(static_cast<float>(std::sin(theta) * std::cos(phi)),
                                  static_cast<float>(std::cos(theta)),
                                  static_cast<float>(-std::sin(theta) * std::sin(phi)));
                // Pattern coordinates: arc lengths along the equator and along a meridian.
                const glm::vec2 uv(static_cast<float>(phi * r), static_cast<float>((kPi / 2 - theta) * r));
                grid.push_back({object.centre + r * n, n, uv, material});
            }
        }
        const auto at = [&](int i, int j) { return grid[static_cast<std::size_t>(j * (segments + 1) + i)]; };
        for (int j = 0; j < rings; ++j)
            for (int i = 0; i < segments; ++i) {
                if (j > 0)
                    addTriangle(at(i, j), at(i + 1, j), at(i + 1, j + 1));
                if (j < rings - 1)
                    addTriangle(at(i, j), at(i + 1, j + 1), at(i, j + 1));
            }
    }

    std::vector<Vertex> vertices;

private:
    static glm::mat3 yawMatrix(float degrees)
    {
        const float a = glm::radians(degrees);
        // Counter-clockwise seen from above (+y): x goes towards -z.
        return glm::mat3(glm::vec3(std::cos(a), 0.0f, -std::sin(a)), glm::vec3(0.0f, 1.0f, 0.0f),
                         glm::vec3(std::sin(a), 0.0f, std::cos(a)));
    }

    /// Appends a triangle wound counter-clockwise seen from outside (where its normals point),
    /// so that back faces can be culled.
    void addTriangle(const Vertex& a, const Vertex& b, const Vertex& c)
    {
        const glm::vec3 face = glm::cross(b.position - a.position, c.position - a.position);
        const bool outward = glm::dot(face, a.normal + b.normal + c.normal) >= 0.0f;
        vertices.push_back(a);
        vertices.push_back(outward ? b : c);
        vertices.push_back(outward ? c : b);
    }
};

MaterialBlock materialBlock(const SurfaceMaterial& m)
{
    return {glm::vec4(m.colorA, static_cast<float>(m.pattern)), glm::vec4(m.colorB, m.scaleM),
            glm::vec4(m.emission, 0.0f, 0.0f, 0.0f)};
}

// ---- GL targets -------------------------------------------------------------------------------

/// A framebuffer with a colour texture and, optionally, a 32-bit float depth buffer.
struct Target {
    gl::Texture color;
    gl::Texture depth;
    gl::Handle<gl::deleteFramebuffer> framebuffer;

    Target(GLenum colorFormat, bool withDepth, int width, int height, const std::string& name)
        : color(colorFormat, width, height, name + " colour")
    {
        GLuint id = 0;
        glCreateFramebuffers(1, &id);
        framebuffer = gl::Handle<gl::deleteFramebuffer>(id);
        glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0, color.id(), 0);
        if (withDepth) {
            depth = gl::Texture(GL_DEPTH_COMPONENT32F, width, height, name + " depth");
            glNamedFramebufferTexture(id, GL_DEPTH_ATTACHMENT, depth.id(), 0);
        }
        if (glCheckNamedFramebufferStatus(id, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw std::runtime_error(fmt::format("defocus::SyntheticScene: the '{}' framebuffer is incomplete", name));
        gl::label(GL_FRAMEBUFFER, id, name);
    }

    void bind() const
    {
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer.id());
        glViewport(0, 0, color.width(), color.height());
    }
};

/// Clears `target` (colour 0, depth far) and sets the state a scene render needs: depth test,
/// back faces culled, no blending.
void beginSceneDraw(const Target& target)
{
    glDepthMask(GL_TRUE); // clears obey the depth mask
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    const float far = 1.0f;
    glClearNamedFramebufferfv(target.framebuffer.id(), GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(target.framebuffer.id(), GL_DEPTH, 0, &far);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    glDisable(GL_BLEND);
}

/// Saves what render() changes of the context's state and puts it back, so that the filter's
/// pipeline, sharing the context, finds it as it left it: the depth test, blending and culling
/// switches as they were; depth, blend and colour-mask settings at GL's defaults; framebuffer,
/// program and vertex array unbound (every pass binds its own).
class StateGuard {
public:
    StateGuard()
        : depthTest_(glIsEnabled(GL_DEPTH_TEST)), blend_(glIsEnabled(GL_BLEND)), cull_(glIsEnabled(GL_CULL_FACE))
    {
    }
    StateGuard(const StateGuard&) = delete;
    StateGuard& operator=(const StateGuard&) = delete;
    ~StateGuard()
    {
        set(GL_DEPTH_TEST, depthTest_);
        set(GL_BLEND, blend_);
        set(GL_CULL_FACE, cull_);
        glDepthMask(GL_TRUE);
        glDepthFunc(GL_LESS);
        glBlendFunc(GL_ONE, GL_ZERO);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glBindVertexArray(0);
        glUseProgram(0);
    }

private:
    static void set(GLenum capability, GLboolean on)
    {
        if (on)
            glEnable(capability);
        else
            glDisable(capability);
    }
    GLboolean depthTest_, blend_, cull_;
};

/// Reads an RGBA32F texture as CV_32FC3 BGR with row 0 at the top (GL's row 0 is the bottom),
/// each value multiplied by `scale`.
cv::Mat readColor(const gl::Texture& texture, double scale)
{
    cv::Mat rgba(texture.height(), texture.width(), CV_32FC4);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureImage(texture.id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(rgba.total() * rgba.elemSize()),
                      rgba.data);
    cv::Mat bgr;
    cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
    cv::flip(bgr, bgr, 0);
    if (scale != 1.0)
        bgr *= scale;
    return bgr;
}

cv::Mat readDepth(const gl::Texture& texture)
{
    cv::Mat depth(texture.height(), texture.width(), CV_32FC1);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureImage(texture.id(), 0, GL_RED, GL_FLOAT, static_cast<GLsizei>(depth.total() * depth.elemSize()),
                      depth.data);
    cv::flip(depth, depth, 0);
    return depth;
}

} // namespace

// ---- sampling ---------------------------------------------------------------------------------

std::vector<glm::dvec2> apertureSamples(int blades, double rotationDeg, int count)
{
    assert(blades >= 3 && count >= 1);
    const int n = blades;
    // Corner k at 90 degrees (straight up) + rotation + k * 360 / n, counter-clockwise in a
    // frame with y up: the image's up, since the camera's +y is the image's top row.
    std::vector<glm::dvec2> corners;
    for (int k = 0; k < n; ++k) {
        const double angle = (90.0 + rotationDeg + 360.0 * k / n) * kPi / 180.0;
        corners.emplace_back(std::cos(angle), std::sin(angle));
    }
    // The polygon is n equal triangles (centre, corner k, corner k+1). The first coordinate of a
    // Hammersley point picks the triangle and, rescaled, the distance from the centre (square
    // root: area grows with its square); the second, the position along the outer edge. Uniform
    // by area, and the set's stratification carries over.
    std::vector<glm::dvec2> points;
    for (int i = 0; i < count; ++i) {
        const glm::dvec2 u = hammersley(i, count);
        const double scaled = u.x * n;
        const int k = std::min(static_cast<int>(scaled), n - 1);
        const double radial = std::sqrt(scaled - k);
        const glm::dvec2 edge = (1.0 - u.y) * corners[static_cast<std::size_t>(k)] +
                                u.y * corners[static_cast<std::size_t>((k + 1) % n)];
        points.push_back(radial * edge);
    }
    return points;
}

std::vector<glm::dvec2> pixelJitter(int count)
{
    assert(count >= 1);
    std::vector<glm::dvec2> offsets;
    for (int i = 0; i < count; ++i)
        offsets.push_back(count == 1 ? glm::dvec2(0.0) : hammersley(i, count) - 0.5);
    return offsets;
}

// ---- the scene --------------------------------------------------------------------------------

std::vector<std::string> validate(const SyntheticSettings& s)
{
    std::vector<std::string> issues;
    const auto outside = [&](const char* name, double value, double lo, double hi) {
        if (!(value >= lo && value <= hi))
            issues.push_back(fmt::format("{} must be between {} and {}, not {}", name, lo, hi, value));
    };
    outside("width", s.width, 16, 4096);
    outside("height", s.height, 16, 4096);
    if (s.frames < 1)
        issues.emplace_back("frames must be at least 1");
    if (!(s.frameRate > 0.0))
        issues.push_back(fmt::format("frame rate {} is not positive", s.frameRate));
    outside("focal length (mm)", s.lens.focalLengthMm, limits::kFocalLengthMm[0], limits::kFocalLengthMm[1]);
    outside("f-number", s.lens.fNumber, limits::kFNumber[0], limits::kFNumber[1]);
    outside("sensor width (mm)", s.lens.sensorWidthMm, limits::kSensorWidthMm[0], limits::kSensorWidthMm[1]);
    if (!s.focusPull && !(s.lens.focusM > s.lens.focalLengthMm * 1e-3))
        issues.push_back(fmt::format("focus {} m is not beyond the focal length", s.lens.focusM));
    outside("blades", s.aperture.blades, 3, 16);
    outside("blade rotation (deg)", s.lens.bladeRotationDeg, -180.0, 180.0);
    outside("reference samples", s.aperture.samples, 1, 65536);
    outside("pinhole samples", s.pinholeSamples, 1, 4096);
    return issues;
}

struct SyntheticScene::State {
    SceneDescription scene;
    SyntheticSettings settings;
    std::size_t triangles = 0;
    gl::Program shade;
    gl::Program depthProgram;
    gl::Handle<gl::deleteBuffer> vertexBuffer;
    gl::Handle<gl::deleteBuffer> materialBuffer;
    gl::Handle<gl::deleteVertexArray> sceneVao;
    gl::UniformBuffer cameraBuffer;
    Target sum;         ///< the running sum of renders: RGBA32F + the current render's depth
    Target depthTarget; ///< planar depth: R32F + depth
    std::vector<glm::dvec2> pinholeJitter;
    std::vector<glm::dvec2> lensPoints;      ///< unit polygon
    std::vector<glm::dvec2> referenceJitter; ///< permuted, one per lens point

    State(SceneDescription sceneIn, SyntheticSettings settingsIn)
        : scene(std::move(sceneIn)), settings(settingsIn),
          shade("synthetic_scene.vert", "synthetic_scene.frag", "synthetic scene"),
          depthProgram("synthetic_scene.vert", "synthetic_scene.frag", "synthetic depth", {"SYNTHETIC_DEPTH 1"}),
          cameraBuffer(sizeof(CameraBlock), "synthetic camera"),
          sum(GL_RGBA32F, true, settings.width, settings.height, "synthetic sum"),
          depthTarget(GL_R32F, true, settings.width, settings.height, "synthetic depth")
    {
        // Drawn nearest first (from the first frame's eye), so that the depth test rejects
        // hidden fragments before they are shaded: on llvmpipe shading is most of a render's cost.
        std::vector<const SceneObject*> order;
        for (const SceneObject& object : scene.objects)
            order.push_back(&object);
        std::stable_sort(order.begin(), order.end(), [&](const SceneObject* a, const SceneObject* b) {
            return glm::distance(a->centre, scene.from.eye) < glm::distance(b->centre, scene.from.eye);
        });
        MeshBuilder mesh;
        std::vector<MaterialBlock> materials;
        for (const SceneObject* objectPointer : order) {
            const SceneObject& object = *objectPointer;
            const auto index = static_cast<std::uint32_t>(materials.size());
            materials.push_back(materialBlock(object.material));
            if (object.shape == SceneObject::Shape::Sphere)
                mesh.addSphere(object, index, scene.from.eye);
            else
                mesh.addBox(object, index);
        }
        if (materials.empty())
            materials.push_back(materialBlock({})); // an empty scene still binds a valid buffer
        triangles = mesh.vertices.size() / 3;

        GLuint id = 0;
        glCreateBuffers(1, &id);
        vertexBuffer = gl::Handle<gl::deleteBuffer>(id);
        glNamedBufferStorage(id, static_cast<GLsizeiptr>(std::max<std::size_t>(mesh.vertices.size(), 1) * sizeof(Vertex)),
                             mesh.vertices.empty() ? nullptr : mesh.vertices.data(), 0);
        gl::label(GL_BUFFER, id, "synthetic vertices");
        glCreateBuffers(1, &id);
        materialBuffer = gl::Handle<gl::deleteBuffer>(id);
        glNamedBufferStorage(id, static_cast<GLsizeiptr>(materials.size() * sizeof(MaterialBlock)), materials.data(), 0);
        gl::label(GL_BUFFER, id, "synthetic materials");

        glCreateVertexArrays(1, &id);
        sceneVao = gl::Handle<gl::deleteVertexArray>(id);
        glVertexArrayVertexBuffer(id, 0, vertexBuffer.id(), 0, sizeof(Vertex));
        const auto attribute = [&](GLuint location, GLint size, std::size_t offset) {
            glEnableVertexArrayAttrib(id, location);
            glVertexArrayAttribFormat(id, location, size, GL_FLOAT, GL_FALSE, static_cast<GLuint>(offset));
            glVertexArrayAttribBinding(id, location, 0);
        };
        attribute(0, 3, offsetof(Vertex, position));
        attribute(1, 3, offsetof(Vertex, normal));
        attribute(2, 2, offsetof(Vertex, uv));
        glEnableVertexArrayAttrib(id, 3);
        glVertexArrayAttribIFormat(id, 3, 1, GL_UNSIGNED_INT, static_cast<GLuint>(offsetof(Vertex, material)));
        glVertexArrayAttribBinding(id, 3, 0);
        gl::label(GL_VERTEX_ARRAY, id, "synthetic scene");

        pinholeJitter = pixelJitter(settings.pinholeSamples);
        lensPoints =
            apertureSamples(settings.aperture.blades, settings.lens.bladeRotationDeg, settings.aperture.samples);
        const std::vector<glm::dvec2> jitter = pixelJitter(settings.aperture.samples);
        for (const int i : permutation(settings.aperture.samples))
            referenceJitter.push_back(jitter[static_cast<std::size_t>(i)]);
    }

    double timeOf(std::size_t index) const
    {
        return settings.frames > 1 ? static_cast<double>(index) / static_cast<double>(settings.frames - 1) : 0.0;
    }

    CameraPose cameraAt(std::size_t index) const
    {
        const float t = static_cast<float>(smoothstep(timeOf(index)));
        return {glm::mix(scene.from.eye, scene.to.eye, t), glm::mix(scene.from.target, scene.to.target, t)};
    }

    LensSettings lensAt(std::size_t index) const
    {
        LensSettings lens = settings.lens;
        if (settings.focusPull)
            lens.focusM = scene.focusFromM + (scene.focusToM - scene.focusFromM) * smoothstep(timeOf(index));
        return lens;
    }

    /// The projection of one render. The lens is a thin lens of focal length f with the sensor
    /// at the image distance v = f S1 / (S1 - f) behind it (S1 the focus distance): the image
    /// width spans the sensor width, so the horizontal half field of view has tangent
    /// sensor / (2 v) (and the vertical one that times height / width). This makes the blur of
    /// a point at depth z, the aperture A = f / N seen through the shifted eyes, exactly
    ///   A |1/S1 - 1/z| v / sensor * width px = A f |z - S1| / (z (S1 - f)) * width / sensor,
    /// the filter's thin-lens CoC (filter/Lens.cpp).
    ///
    /// The eye sits at `lens` (metres, in the lens plane, camera x right / y up). Seen from it,
    /// a point at camera coordinates q (relative to the eye) and depth d = -q.z must land where
    /// the lens centre sees the point of the focus plane it passes through, so that the focus
    /// plane stays fixed: x_ndc = q.x / (d tan) + lens.x / (S1 tan), an off-axis (sheared)
    /// frustum. `jitterPx` moves the image by a fraction of a pixel (antialiasing).
    glm::mat4 projection(const LensSettings& lens, glm::dvec2 lensOffsetM, glm::dvec2 jitterPx) const
    {
        const double f = lens.focalLengthMm * 1e-3;
        const double inverseFocus = std::isinf(lens.focusM) ? 0.0 : 1.0 / lens.focusM;
        const double imageDistance = f / (1.0 - f * inverseFocus); // v = f S1 / (S1 - f)
        // A renderer's camera (FieldOfView::FocalLength) keeps the sensor at f: the blur is
        // then A |1/S1 - 1/z| f / sensor * width px, as filter/Lens.cpp has it for that case.
        const double sensorDistance = lens.fieldOfView == FieldOfView::ImageDistance ? imageDistance : f;
        const double tanX = lens.sensorWidthMm * 1e-3 / (2.0 * sensorDistance);
        const double tanY = tanX * settings.height / settings.width;
        // x_clip = q.x / tanX + shift * d with d = -q.z, so the q.z coefficient is -shift.
        const double shiftX = lensOffsetM.x * inverseFocus / tanX + 2.0 * jitterPx.x / settings.width;
        const double shiftY = lensOffsetM.y * inverseFocus / tanY + 2.0 * jitterPx.y / settings.height;
        glm::mat4 p(0.0f);
        p[0][0] = static_cast<float>(1.0 / tanX);
        p[1][1] = static_cast<float>(1.0 / tanY);
        p[2][0] = static_cast<float>(-shiftX);
        p[2][1] = static_cast<float>(-shiftY);
        p[2][2] = -(kFarM + kNearM) / (kFarM - kNearM);
        p[2][3] = -1.0f;
        p[3][2] = -2.0f * kFarM * kNearM / (kFarM - kNearM);
        return p;
    }

    void drawScene(const glm::mat4& viewProjection, const glm::mat4& view)
    {
        const CameraBlock block{viewProjection, view};
        cameraBuffer.update(&block, sizeof(block));
        cameraBuffer.bind(0);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, materialBuffer.id());
        glBindVertexArray(sceneVao.id());
        glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(triangles * 3));
    }

    /// Averages renders from eyes at `lensPointsM` (metres) with pixel offsets `jitter` (one each).
    /// Each render goes straight into the running sum: a depth-only pass finds the nearest
    /// surface of that render, then the shading pass adds exactly those fragments (depth test
    /// EQUAL, additive float32 blending). Both programs declare gl_Position invariant, so they
    /// compute bit-identical depths.
    cv::Mat accumulateRenders(const LensSettings& lens, const glm::mat4& view,
                              const std::vector<glm::dvec2>& lensPointsM, const std::vector<glm::dvec2>& jitter)
    {
        assert(lensPointsM.size() == jitter.size() && !jitter.empty());
        const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        const float far = 1.0f;
        sum.bind();
        glClearNamedFramebufferfv(sum.framebuffer.id(), GL_COLOR, 0, zero);
        glEnable(GL_DEPTH_TEST);
        glEnable(GL_CULL_FACE);
        glCullFace(GL_BACK);
        glFrontFace(GL_CCW);
        glBlendEquation(GL_FUNC_ADD);
        glBlendFunc(GL_ONE, GL_ONE);
        for (std::size_t i = 0; i < jitter.size(); ++i) {
            const glm::dvec2 a = lensPointsM[i];
            const glm::mat4 eyeView =
                glm::translate(glm::mat4(1.0f), glm::vec3(static_cast<float>(-a.x), static_cast<float>(-a.y), 0.0f)) *
                view;
            const glm::mat4 viewProjection = projection(lens, a, jitter[i]) * eyeView;

            glDepthMask(GL_TRUE); // clears obey the depth mask
            glClearNamedFramebufferfv(sum.framebuffer.id(), GL_DEPTH, 0, &far);
            glDepthFunc(GL_LESS);
            glDisable(GL_BLEND);
            glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
            depthProgram.use();
            drawScene(viewProjection, view);

            glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
            glDepthMask(GL_FALSE);
            glDepthFunc(GL_EQUAL);
            glEnable(GL_BLEND);
            shade.use();
            drawScene(viewProjection, view);
        }
        glDepthMask(GL_TRUE);
        glDepthFunc(GL_LESS);
        glDisable(GL_BLEND);
        return readColor(sum.color, 1.0 / static_cast<double>(jitter.size()));
    }
};

SyntheticScene::SyntheticScene(SceneDescription scene, SyntheticSettings settings)
{
    if (const auto issues = validate(settings); !issues.empty())
        throw std::invalid_argument(fmt::format("defocus::SyntheticScene: {}", fmt::join(issues, "; ")));
    StateGuard guard;
    state_ = std::make_unique<State>(std::move(scene), settings);
}

SyntheticScene::SyntheticScene(SyntheticScene&&) noexcept = default;
SyntheticScene& SyntheticScene::operator=(SyntheticScene&&) noexcept = default;
SyntheticScene::~SyntheticScene() = default;

const SceneDescription& SyntheticScene::description() const { return state_->scene; }
const SyntheticSettings& SyntheticScene::settings() const { return state_->settings; }
std::size_t SyntheticScene::triangleCount() const { return state_->triangles; }
LensSettings SyntheticScene::lensAt(std::size_t index) const { return state_->lensAt(index); }
CameraPose SyntheticScene::cameraAt(std::size_t index) const { return state_->cameraAt(index); }

SyntheticImages SyntheticScene::render(std::size_t index, bool withReference)
{
    assert(index < state_->settings.frames);
    State& s = *state_;
    StateGuard guard;
    SyntheticImages out;
    out.lens = s.lensAt(index);
    const CameraPose pose = s.cameraAt(index);
    const glm::mat4 view = glm::lookAt(pose.eye, pose.target, glm::vec3(0.0f, 1.0f, 0.0f));

    // Depth: one render from the lens centre at the pixel centres, not antialiased (an edge
    // pixel holds the nearer or the farther depth, never a blend), planar along the view axis.
    s.depthTarget.bind();
    beginSceneDraw(s.depthTarget);
    s.depthProgram.use();
    s.drawScene(s.projection(out.lens, glm::dvec2(0.0), glm::dvec2(0.0)) * view, view);
    out.frame.depth = readDepth(s.depthTarget.color);

    // Pinhole colour: the lens centre only, averaged over sub-pixel offsets.
    const std::vector<glm::dvec2> centre(s.pinholeJitter.size(), glm::dvec2(0.0));
    out.frame.color = s.accumulateRenders(out.lens, view, centre, s.pinholeJitter);
    out.frame.index = index;
    out.frame.timestampS = static_cast<double>(index) / s.settings.frameRate;
    out.frame.name = fmt::format("synthetic/{}/{:04d}", s.scene.name, index);

    if (withReference) {
        const auto start = std::chrono::steady_clock::now();
        // Lens points in metres: the unit polygon scaled to the aperture's circumradius f / 2N.
        const double radius = out.lens.focalLengthMm * 1e-3 / (2.0 * out.lens.fNumber);
        std::vector<glm::dvec2> lensPointsM;
        for (const glm::dvec2& p : s.lensPoints)
            lensPointsM.push_back(radius * p);
        out.reference = s.accumulateRenders(out.lens, view, lensPointsM, s.referenceJitter);
        out.referenceMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    return out;
}

} // namespace defocus
