// SPDX-License-Identifier: LGPL-2.1-or-later
// Ground truth the project renders itself: procedural 3D scenes rasterised with GL, giving the
// filter's input (pinhole colour + planar depth) and a thin-lens reference for the same frame,
// accumulated from many renders through points of a polygonal aperture (Haeberli and Akeley 1990).
// How the reference is made, and how it compares with the Cycles truth: docs/synthetic.md.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <opencv2/core.hpp>

#include "defocus/Frame.hpp"
#include "filter/Settings.hpp"

namespace defocus {

/// Procedural surface patterns, evaluated in the fragment shader (no texture images).
enum class Pattern {
    Flat,    ///< colorA
    Checker, ///< squares of side scaleM, colorA and colorB (box-filtered, so it does not alias)
    Stripes, ///< stripes of width scaleM along the surface's first coordinate (box-filtered)
    Noise,   ///< value-noise fBm with features of about scaleM, between colorA and colorB
    Bricks   ///< bricks scaleM high and 2 scaleM long in colorA, mortar in colorB
};

struct SurfaceMaterial {
    Pattern pattern = Pattern::Flat;
    /// Linear albedo, [0, 1] per channel; for an emitter, the colour of the light.
    glm::vec3 colorA{0.5f};
    /// Second albedo of the pattern, [0, 1] per channel.
    glm::vec3 colorB{0.2f};
    /// Pattern period, metres along the surface, > 0.
    float scaleM = 0.5f;
    /// > 0: the surface emits colorA * emission (linear radiance, HDR; highlights use 20-100) and
    /// is not lit. 0: a diffuse surface lit by a sun and a sky.
    float emission = 0.0f;
};

struct SceneObject {
    enum class Shape { Sphere, Box };
    Shape shape = Shape::Box;
    /// Centre, metres, world space (y up; the cameras of the named scenes look towards -z).
    glm::vec3 centre{0.0f};
    /// Box: half extents, metres. Sphere: halfSize.x is the radius.
    glm::vec3 halfSize{0.5f};
    /// Rotation about the vertical axis through the centre, degrees counter-clockwise from above.
    float yawDeg = 0.0f;
    SurfaceMaterial material;
};

/// Where the camera (the centre of its lens) is and what it looks at; the image's up is the
/// world's +y projected.
struct CameraPose {
    glm::vec3 eye{0.0f, 1.5f, 0.0f};
    glm::vec3 target{0.0f, 1.5f, -1.0f};
};

/// A scene and its shot: the camera and the focus move from the first frame's value to the last
/// frame's with an ease-in-out (smoothstep) over the clip.
struct SceneDescription {
    std::string name;
    std::vector<SceneObject> objects;
    CameraPose from;
    CameraPose to;
    /// Focus pull: planar focus distance at the first and the last frame, metres (> focal length).
    double focusFromM = 2.0;
    double focusToM = 2.0;
};

/// The named scenes: "spheres" (a garden of textured spheres, boxes and HDR highlights at
/// 1.5-25 m in front of a brick wall, focus pulled from near to far) and "edges" (poles and
/// wires a few pixels wide, depth steps and highlights against striped and checkered walls, the
/// camera trucking sideways).
std::vector<std::string> syntheticSceneNames();
/// Throws std::invalid_argument naming the known scenes when `name` is not one of them.
SceneDescription syntheticScene(std::string_view name);

/// The aperture: a regular polygon whose circumscribed diameter is focal length / f-number
/// (vertex to vertex, the same diameter the filter's hexagon CoC measures), rotated by the
/// lens's bladeRotationDeg: degrees counter-clockwise as seen in the output image, 0 = one
/// corner straight up in the image (what Blender Cycles renders for 6 blades at rotation 0), as
/// the filter's hexagon. Behind the focus plane the bokeh has this orientation; in front of it,
/// point-reflected (the same for even blade counts).
struct ApertureSettings {
    /// Blade count = corners of the polygon, [3, 16].
    int blades = 6;
    /// Lens positions the reference averages, [1, 65536]. Each is one full render.
    int samples = 256;
};

struct SyntheticSettings {
    /// Image size, pixels, [16, 4096].
    int width = 640;
    int height = 480;
    /// Clip length, frames, >= 1; the shot's animation spans it.
    std::size_t frames = 60;
    /// Frame rate, Hz, > 0 (timestamps and video sinks).
    double frameRate = 30.0;
    /// Focal length, f-number, sensor width and blade rotation drive the camera; focusM is used
    /// on every frame unless focusPull. model and maxCocPx are the filter's business, ignored here.
    LensSettings lens;
    /// true: the focus follows the scene's pull (focusFromM -> focusToM); false: lens.focusM.
    bool focusPull = true;
    ApertureSettings aperture;
    /// Sub-pixel positions averaged for the pinhole colour, [1, 4096]: the pinhole image is
    /// antialiased with a box filter over the pixel, as the reference is (docs/synthetic.md).
    int pinholeSamples = 16;
};

/// Checks every field; returns one message per problem (empty when all is well).
std::vector<std::string> validate(const SyntheticSettings& settings);

/// One rendered frame.
struct SyntheticImages {
    /// The filter's input: colour CV_32FC3 (linear BGR, HDR), depth CV_32FC1 (planar, metres,
    /// not antialiased), index, timestamp and a name like "synthetic/spheres/0003".
    Frame frame;
    /// Thin-lens reference, CV_32FC3 linear BGR, same size; empty when not asked for.
    cv::Mat reference;
    /// The lens of this frame (the focus of the pull when settings.focusPull).
    LensSettings lens;
    /// Wall time of the reference alone (its renders and readback), milliseconds; 0 without it.
    double referenceMs = 0.0;
};

/// Renders a SceneDescription with an OpenGL 4.5 context that must be current on the calling
/// thread for the scene's whole life (gl::EglContext; it can be the one the filter runs in:
/// render() puts back the depth-test, blend and cull switches it found and leaves framebuffer 0
/// bound). Move-only.
class SyntheticScene {
public:
    /// Uploads the geometry and builds the shaders. Throws std::invalid_argument for bad
    /// settings (validate()) and gl::ShaderError when a shader does not build.
    SyntheticScene(SceneDescription scene, SyntheticSettings settings);
    SyntheticScene(SyntheticScene&&) noexcept;
    SyntheticScene& operator=(SyntheticScene&&) noexcept;
    ~SyntheticScene();

    /// Renders frame `index` (< settings.frames): the pinhole colour and the depth always, the
    /// thin-lens reference (aperture.samples renders) only when `withReference`.
    SyntheticImages render(std::size_t index, bool withReference = true);
    /// The lens and the camera of frame `index`, without rendering.
    LensSettings lensAt(std::size_t index) const;
    CameraPose cameraAt(std::size_t index) const;

    const SceneDescription& description() const;
    const SyntheticSettings& settings() const;
    std::size_t triangleCount() const;

    struct State; ///< GL objects and geometry, defined in the .cpp

private:
    std::unique_ptr<State> state_;
};

/// `count` points spread uniformly by area over the regular polygon of `blades` corners with
/// circumradius 1, rotated by `rotationDeg` (see ApertureSettings; x right, y up as seen in the
/// image): a Hammersley set mapped into the polygon's triangles, so every triangle gets its
/// share and the points are stratified.
std::vector<glm::dvec2> apertureSamples(int blades, double rotationDeg, int count);
/// `count` sub-pixel offsets in [-0.5, 0.5)^2 (a Hammersley set): the box filter of a pixel.
std::vector<glm::dvec2> pixelJitter(int count);

} // namespace defocus
