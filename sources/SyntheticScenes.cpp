// SPDX-License-Identifier: LGPL-2.1-or-later
// The named synthetic scenes: geometry, materials, and the shot (camera move and focus pull).
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <glm/trigonometric.hpp>

#include "sources/SyntheticScene.hpp"

namespace defocus {

namespace {

// Sizes are chosen for the default camera, 50 mm on a 36 mm sensor over 640 px, where a pixel at
// depth z spans z * 36 / (50 * 640) = 1.125 mm per metre of depth (other lenses zoom, and the
// filter's CoC follows). kEye is the lens height; the first frame looks level along -z.
constexpr float kEyeHeight = 1.2f;
constexpr float kMetresPerPixelPerMetre = 36.0f / (50.0f * 640.0f);

/// A point at planar depth `depth` whose image, from the first frame's camera at 50 mm, is at
/// (sx, sy) in [-1, 1]^2 (x right, y up); `y` overrides the height when given.
glm::vec3 at(float sx, float sy, float depth)
{
    const float tanX = 0.36f, tanY = 0.27f; // 18 / 50 and 13.5 / 50
    return {sx * depth * tanX, kEyeHeight + sy * depth * tanY, -depth};
}

/// The radius of a sphere `pixels` wide at `depth` for the default camera.
float radiusForPixels(float pixels, float depth)
{
    return 0.5f * pixels * depth * kMetresPerPixelPerMetre;
}

SurfaceMaterial surface(Pattern pattern, glm::vec3 a, glm::vec3 b, float scaleM)
{
    return {pattern, a, b, scaleM, 0.0f};
}

SurfaceMaterial light(glm::vec3 colour, float emission)
{
    return {Pattern::Flat, colour, glm::vec3(0.0f), 1.0f, emission};
}

SceneObject sphere(glm::vec3 centre, float radius, SurfaceMaterial material)
{
    return {SceneObject::Shape::Sphere, centre, glm::vec3(radius), 0.0f, material};
}

SceneObject box(glm::vec3 centre, glm::vec3 halfSize, float yawDeg, SurfaceMaterial material)
{
    return {SceneObject::Shape::Box, centre, halfSize, yawDeg, material};
}

/// A sphere resting on the ground at planar depth `depth`, its centre at image x `sx`.
SceneObject groundSphere(float sx, float depth, float radius, SurfaceMaterial material)
{
    glm::vec3 c = at(sx, 0.0f, depth);
    c.y = radius;
    return sphere(c, radius, material);
}

SceneObject groundBox(float sx, float depth, glm::vec3 halfSize, float yawDeg, SurfaceMaterial material)
{
    glm::vec3 c = at(sx, 0.0f, depth);
    c.y = halfSize.y;
    return box(c, halfSize, yawDeg, material);
}

const glm::vec3 kWarm{1.0f, 0.78f, 0.5f}, kWhite{1.0f, 1.0f, 1.0f}, kCool{0.55f, 0.8f, 1.0f}, kPink{1.0f, 0.45f, 0.65f};

/// A garden of textured spheres and boxes at 1.5-16 m and HDR highlights at 1.8-25 m in front
/// of a brick wall 25 m away, on a checkered ground: a close analogue of the Blender scene
/// (data/blender_spheres). The focus pulls from the near spheres (1.8 m) to the far ones (12 m)
/// while the camera dollies in 0.4 m and pans slightly right.
SceneDescription spheres()
{
    SceneDescription s;
    s.name = "spheres";
    auto& o = s.objects;
    o.push_back(box({0.0f, -0.05f, -20.0f}, {60.0f, 0.05f, 40.0f}, 0.0f,
                    surface(Pattern::Checker, {0.75f, 0.75f, 0.72f}, {0.06f, 0.06f, 0.06f}, 1.0f)));
    o.push_back(box({0.0f, 15.0f, -25.5f}, {60.0f, 15.0f, 0.5f}, 0.0f,
                    surface(Pattern::Bricks, {0.42f, 0.15f, 0.08f}, {0.55f, 0.55f, 0.52f}, 0.25f)));

    // Floating spheres near the lens, resting ones farther away.
    o.push_back(sphere(at(-0.55f, -0.5f, 1.6f), 0.16f,
                       surface(Pattern::Noise, {0.05f, 0.45f, 0.08f}, {0.5f, 0.8f, 0.3f}, 0.06f)));
    o.push_back(sphere(at(0.62f, 0.55f, 2.0f), 0.2f,
                       surface(Pattern::Checker, {0.05f, 0.15f, 0.7f}, {0.85f, 0.85f, 0.85f}, 0.07f)));
    o.push_back(sphere(at(-0.05f, -0.3f, 3.0f), 0.3f,
                       surface(Pattern::Checker, {0.7f, 0.06f, 0.05f}, {0.85f, 0.85f, 0.85f}, 0.1f)));
    o.push_back(sphere(at(-0.6f, 0.3f, 4.5f), 0.35f,
                       surface(Pattern::Noise, {0.35f, 0.08f, 0.45f}, {0.8f, 0.6f, 0.85f}, 0.12f)));
    o.push_back(groundSphere(0.42f, 5.0f, 0.5f, surface(Pattern::Stripes, {0.85f, 0.7f, 0.05f}, {0.15f, 0.1f, 0.02f}, 0.1f)));
    o.push_back(groundSphere(-0.2f, 7.0f, 0.6f, surface(Pattern::Checker, {0.9f, 0.5f, 0.05f}, {0.25f, 0.12f, 0.04f}, 0.2f)));
    o.push_back(groundSphere(0.15f, 12.0f, 0.9f, surface(Pattern::Noise, {0.02f, 0.35f, 0.35f}, {0.5f, 0.9f, 0.85f}, 0.25f)));
    o.push_back(groundSphere(0.75f, 14.0f, 1.0f, surface(Pattern::Checker, {0.8f, 0.8f, 0.8f}, {0.1f, 0.3f, 0.1f}, 0.3f)));
    o.push_back(groundSphere(-0.8f, 16.0f, 1.2f, surface(Pattern::Stripes, {0.9f, 0.9f, 0.9f}, {0.6f, 0.1f, 0.1f}, 0.25f)));

    o.push_back(box(at(0.28f, -0.62f, 2.5f), glm::vec3(0.12f), 35.0f,
                    surface(Pattern::Checker, {0.9f, 0.9f, 0.9f}, {0.03f, 0.03f, 0.03f}, 0.06f)));
    o.push_back(groundBox(-0.35f, 6.0f, {0.45f, 0.45f, 0.45f}, 25.0f,
                          surface(Pattern::Stripes, {0.1f, 0.1f, 0.1f}, {0.85f, 0.85f, 0.8f}, 0.1f)));
    o.push_back(groundBox(0.85f, 9.0f, {0.6f, 0.9f, 0.6f}, -30.0f,
                          surface(Pattern::Checker, {0.45f, 0.1f, 0.55f}, {0.9f, 0.9f, 0.9f}, 0.3f)));
    o.push_back(groundBox(-0.05f, 18.0f, {0.5f, 2.5f, 0.5f}, 10.0f,
                          surface(Pattern::Bricks, {0.7f, 0.65f, 0.5f}, {0.3f, 0.3f, 0.3f}, 0.2f)));

    // Highlights, 3-5 px wide through the pinhole, 20-100 times a white surface: on the wall
    // (25 m), in mid-air among the spheres, and a few in front of the focus.
    const struct {
        float sx, sy, depth, pixels;
        glm::vec3 colour;
        float emission;
    } lights[] = {
        {-0.82f, 0.85f, 24.9f, 4.0f, kWarm, 40.0f},  {-0.55f, 0.62f, 24.9f, 4.0f, kWhite, 20.0f},
        {-0.25f, 0.8f, 24.9f, 5.0f, kWarm, 80.0f},   {0.05f, 0.55f, 24.9f, 4.0f, kCool, 40.0f},
        {0.32f, 0.88f, 24.9f, 4.0f, kWhite, 100.0f}, {0.58f, 0.6f, 24.9f, 4.0f, kPink, 40.0f},
        {0.85f, 0.78f, 24.9f, 5.0f, kWarm, 60.0f},   {-0.7f, 0.35f, 24.9f, 3.0f, kCool, 60.0f},
        {0.2f, 0.3f, 24.9f, 3.0f, kWhite, 50.0f},    {0.35f, 0.42f, 12.0f, 5.0f, kWarm, 80.0f},
        {-0.4f, 0.55f, 10.0f, 4.0f, kWhite, 50.0f},  {0.7f, 0.25f, 8.0f, 4.0f, kCool, 30.0f},
        {-0.15f, 0.45f, 6.0f, 4.0f, kPink, 30.0f},   {0.3f, -0.15f, 3.5f, 4.0f, kWarm, 40.0f},
        {-0.75f, 0.7f, 2.2f, 3.0f, kWhite, 60.0f},   {0.5f, -0.7f, 1.8f, 3.0f, kWarm, 40.0f},
    };
    for (const auto& l : lights)
        o.push_back(sphere(at(l.sx, l.sy, l.depth), radiusForPixels(l.pixels, l.depth), light(l.colour, l.emission)));

    s.from = {{0.0f, kEyeHeight, 0.0f}, {0.0f, kEyeHeight, -10.0f}};
    s.to = {{0.15f, kEyeHeight + 0.05f, -0.4f}, {0.45f, kEyeHeight, -10.4f}};
    s.focusFromM = 1.8;
    s.focusToM = 12.0;
    return s;
}

/// Thin objects and depth steps: poles 1.5-8 px wide at 1.6-6 m, horizontal wires 2-3 px thick
/// and one receding from 2 to 6 m, a staircase of fronto-parallel panels at 1.8-5.5 m, boxes,
/// highlights, against a checkered wall 9 m away. The camera trucks 0.3 m sideways (parallax at
/// every edge) while the focus pulls from 2 m to 6 m.
SceneDescription edges()
{
    SceneDescription s;
    s.name = "edges";
    auto& o = s.objects;
    o.push_back(box({0.0f, -0.05f, -10.0f}, {40.0f, 0.05f, 20.0f}, 0.0f,
                    surface(Pattern::Checker, {0.7f, 0.7f, 0.68f}, {0.12f, 0.1f, 0.08f}, 0.5f)));
    o.push_back(box({0.0f, 10.0f, -9.5f}, {40.0f, 10.0f, 0.5f}, 0.0f,
                    surface(Pattern::Checker, {0.85f, 0.85f, 0.82f}, {0.05f, 0.06f, 0.08f}, 0.15f)));

    // Poles: width in pixels at their depth, full height, in bright albedos against the wall.
    const struct {
        float sx, depth, pixels;
        glm::vec3 colour;
    } poles[] = {
        {-0.88f, 1.6f, 8.0f, {0.9f, 0.9f, 0.9f}},  {-0.12f, 2.0f, 2.0f, {0.9f, 0.2f, 0.1f}},
        {0.08f, 3.0f, 4.0f, {0.95f, 0.8f, 0.1f}},  {0.3f, 4.5f, 3.0f, {0.1f, 0.6f, 0.9f}},
        {0.48f, 6.0f, 6.0f, {0.9f, 0.9f, 0.9f}},   {-0.32f, 5.0f, 1.5f, {0.95f, 0.95f, 0.95f}},
    };
    for (const auto& p : poles) {
        const float half = 0.5f * p.pixels * p.depth * kMetresPerPixelPerMetre;
        glm::vec3 c = at(p.sx, 0.0f, p.depth);
        c.y = 3.0f;
        o.push_back(box(c, {half, 3.0f, half}, 0.0f, surface(Pattern::Flat, p.colour, p.colour, 1.0f)));
    }
    // Wires: horizontal, 2-3 px thick, dark against the wall, and a white one receding in depth.
    const struct {
        float sy, depth, pixels;
    } wires[] = {{0.62f, 2.5f, 2.0f}, {0.4f, 4.0f, 3.0f}, {0.8f, 7.0f, 2.0f}};
    for (const auto& w : wires) {
        const float half = 0.5f * w.pixels * w.depth * kMetresPerPixelPerMetre;
        o.push_back(box(at(0.0f, w.sy, w.depth), {8.0f, half, half}, 0.0f,
                        surface(Pattern::Flat, {0.05f, 0.05f, 0.05f}, {0.05f, 0.05f, 0.05f}, 1.0f)));
    }
    {
        const glm::vec3 nearEnd = at(-0.5f, 0.25f, 2.0f), farEnd = at(0.9f, 0.25f, 6.0f);
        const glm::vec3 mid = 0.5f * (nearEnd + farEnd);
        const glm::vec3 d = farEnd - nearEnd;
        const float length = 0.5f * std::sqrt(d.x * d.x + d.z * d.z);
        const float yaw = glm::degrees(std::atan2(-d.z, d.x)); // from +x towards -z
        const float half = 0.5f * 2.5f * 3.0f * kMetresPerPixelPerMetre;
        o.push_back(box({mid.x, nearEnd.y, mid.z}, {length, half, half}, yaw,
                        surface(Pattern::Flat, {0.9f, 0.9f, 0.9f}, {0.9f, 0.9f, 0.9f}, 1.0f)));
    }
    // Depth steps: panels facing the lens at the lower left, each farther one peeking out to
    // the right of and above the nearer one.
    const struct {
        float innerSx, topSy, depth;
        SurfaceMaterial material;
    } steps[] = {
        {-0.75f, -0.25f, 1.8f, surface(Pattern::Noise, {0.6f, 0.3f, 0.1f}, {0.95f, 0.8f, 0.5f}, 0.04f)},
        {-0.55f, -0.1f, 2.6f, surface(Pattern::Checker, {0.1f, 0.3f, 0.7f}, {0.9f, 0.9f, 0.9f}, 0.06f)},
        {-0.35f, 0.05f, 3.8f, surface(Pattern::Stripes, {0.9f, 0.9f, 0.9f}, {0.1f, 0.1f, 0.1f}, 0.04f)},
        {-0.15f, 0.2f, 5.5f, surface(Pattern::Bricks, {0.5f, 0.2f, 0.1f}, {0.6f, 0.6f, 0.55f}, 0.08f)},
    };
    for (const auto& st : steps) {
        const glm::vec3 corner = at(st.innerSx, st.topSy, st.depth);
        const float halfWidth = 3.0f;
        o.push_back(box({corner.x - halfWidth, 0.5f * corner.y, corner.z}, {halfWidth, 0.5f * corner.y, 0.05f}, 0.0f,
                        st.material));
    }
    // Boxes at the lower right (the ground is out of the picture nearer than 4.4 m): a slim
    // pedestal at 3 m before a wide block at 4.5 m.
    o.push_back(groundBox(0.6f, 3.0f, {0.12f, 0.75f, 0.12f}, 20.0f,
                          surface(Pattern::Checker, {0.9f, 0.9f, 0.9f}, {0.05f, 0.05f, 0.05f}, 0.05f)));
    o.push_back(groundBox(0.85f, 4.5f, {0.3f, 0.6f, 0.25f}, -15.0f,
                          surface(Pattern::Noise, {0.1f, 0.4f, 0.15f}, {0.7f, 0.9f, 0.5f}, 0.08f)));

    const struct {
        float sx, sy, depth, pixels;
        glm::vec3 colour;
        float emission;
    } lights[] = {
        {-0.05f, 0.72f, 8.9f, 4.0f, kWarm, 60.0f}, {0.4f, 0.55f, 8.9f, 4.0f, kWhite, 100.0f},
        {0.85f, 0.85f, 8.9f, 4.0f, kCool, 40.0f},  {-0.6f, 0.45f, 8.9f, 3.0f, kWhite, 50.0f},
        {0.2f, 0.05f, 3.5f, 4.0f, kWarm, 50.0f},   {-0.45f, 0.85f, 2.2f, 3.0f, kPink, 40.0f},
    };
    for (const auto& l : lights)
        o.push_back(sphere(at(l.sx, l.sy, l.depth), radiusForPixels(l.pixels, l.depth), light(l.colour, l.emission)));

    s.from = {{-0.15f, kEyeHeight, 0.0f}, {-0.15f, kEyeHeight, -10.0f}};
    s.to = {{0.15f, kEyeHeight, 0.0f}, {0.15f, kEyeHeight, -10.0f}};
    s.focusFromM = 2.0;
    s.focusToM = 6.0;
    return s;
}

} // namespace

std::vector<std::string> syntheticSceneNames()
{
    return {"spheres", "edges"};
}

SceneDescription syntheticScene(std::string_view name)
{
    if (name == "spheres")
        return spheres();
    if (name == "edges")
        return edges();
    throw std::invalid_argument(fmt::format("defocus::syntheticScene: no scene called '{}' (known: {})", name,
                                            fmt::join(syntheticSceneNames(), ", ")));
}

} // namespace defocus
