// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-synthetic: renders a synthetic scene's frame - the filter's input (pinhole colour, planar
// depth) and the thin-lens reference - to files, and times the reference (docs/synthetic.md).
//   defocus-synthetic --scene spheres --frame 0 -o out/synthetic
//   defocus-synthetic --scene edges --focal-length 85 --f-number 1.4 --focus 5 --samples 1024 -o out/edges
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>

#include "bench/BenchCli.hpp"
#include "filter/ColorSpace.hpp"
#include "filter/gl/EglContext.hpp"
#include "samples/CliOptions.hpp"
#include "samples/ExitStatus.hpp"
#include "sinks/FrameSink.hpp"
#include "sinks/ImageSinks.hpp"
#include "sources/ImageIO.hpp"
#include "sources/SyntheticScene.hpp"

namespace {

using namespace defocus;
namespace fs = std::filesystem;

/// Exit statuses as defocus's (ExitStatus.hpp): 0 done, 1 output, 2 command line, 75 no GL.

/// The files written into the output folder; the reference's only with it.
std::vector<std::string> outputFiles(bool reference)
{
    std::vector<std::string> files{"color.exr", "color.png", "depth.exr"};
    if (reference)
        files.insert(files.end(), {"reference.exr", "reference.png"});
    return files;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"defocus-synthetic: render a synthetic scene's input (colour, depth) and thin-lens reference"};
    std::string sceneName = "spheres";
    std::string out = "out/synthetic";
    std::size_t frame = 0;
    std::string focus = "pull";
    std::string fov = "image-distance";
    SyntheticSettings settings;
    int runs = 1;
    bool noReference = false;
    app.add_option("--scene", sceneName, "Scene: spheres or edges")->capture_default_str();
    app.add_option("--frame", frame, "Frame index of the shot")->capture_default_str();
    app.add_option("--frames", settings.frames, "Shot length, frames")->capture_default_str();
    app.add_option("-o,--output", out, "Output folder: color.exr, depth.exr, reference.exr and PNG previews")
        ->capture_default_str();
    app.add_option("--width", settings.width, "Image width, pixels")->capture_default_str();
    app.add_option("--height", settings.height, "Image height, pixels")->capture_default_str();
    app.add_option("--focal-length", settings.lens.focalLengthMm, "Focal length, millimetres")->capture_default_str();
    app.add_option("--f-number", settings.lens.fNumber, "f-number")->capture_default_str();
    app.add_option("--sensor-width", settings.lens.sensorWidthMm, "Sensor width, millimetres")->capture_default_str();
    app.add_option("--fov-from", fov, "Where the sensor width spans the image: image-distance (a real "
                   "camera, whose view narrows as it focuses closer) or focal-length (Blender, game engines)")
        ->check(CLI::IsMember({"image-distance", "focal-length"}))
        ->capture_default_str();
    app.add_option("--focus", focus, "Focus distance, metres, or 'pull' for the scene's focus pull")
        ->capture_default_str();
    app.add_option("--samples", settings.aperture.samples, "Lens positions the reference averages")
        ->capture_default_str();
    app.add_option("--pinhole-samples", settings.pinholeSamples, "Sub-pixel positions of the pinhole colour")
        ->capture_default_str();
    app.add_option("--blades", settings.aperture.blades, "Aperture blades")->capture_default_str();
    app.add_option("--blade-rotation", settings.lens.bladeRotationDeg,
                   "Degrees counter-clockwise in the image; 0 = a corner straight up")
        ->capture_default_str();
    app.add_option("--runs", runs, "Render the reference this many times and print each time")->check(cli::between(1, 100));
    app.add_flag("--no-reference", noReference, "Only the pinhole colour and the depth");
    bool overwrite = false;
    app.add_flag("-y,--overwrite", overwrite, "Replace output files that exist (without it, an existing one is refused)");
    if (const auto status = cli::parse(app, argc, argv))
        return *status;
    cli::logToStderr("defocus-synthetic");
    parseFieldOfView(fov, settings.lens.fieldOfView); // checked by CLI11

    if (focus != "pull") {
        try {
            settings.lens.focusM = std::stod(focus);
        } catch (const std::exception&) {
            spdlog::error("--focus '{}' is neither metres nor 'pull'", focus);
            return kExitUsage;
        }
        settings.focusPull = false;
    }
    if (const auto issues = validate(settings); !issues.empty()) {
        for (const auto& issue : issues)
            spdlog::error("{}", issue);
        return kExitUsage;
    }
    if (frame >= settings.frames) {
        spdlog::error("--frame {} is not below --frames {}", frame, settings.frames);
        return kExitUsage;
    }
    enableOpenExr(); // before OpenCV's first EXR write
    try {
        // The output, as defocus's: its folder's parent exists, and no file is replaced without -y.
        requireParentFolder(fs::path(out) / "", true);
        for (const std::string& file : outputFiles(!noReference))
            refuseExisting(fs::path(out) / file, overwrite);
        auto context = gl::EglContext::create();
        SyntheticScene scene(syntheticScene(sceneName), settings);
        fmt::print("{} on {}: {} triangles, {}x{}\n", sceneName, context.info().glRenderer, scene.triangleCount(),
                   settings.width, settings.height);
        SyntheticImages images;
        for (int run = 0; run < runs; ++run) {
            const auto start = std::chrono::steady_clock::now();
            images = scene.render(frame, !noReference);
            const double totalMs =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            fmt::print("input (depth + {} pinhole renders): {:.0f} ms", settings.pinholeSamples,
                       totalMs - images.referenceMs);
            if (!noReference)
                fmt::print("; reference: {} renders in {:.0f} ms ({:.2f} ms per render)", settings.aperture.samples,
                           images.referenceMs, images.referenceMs / settings.aperture.samples);
            fmt::print("\n");
        }
        const LensSettings& lens = images.lens;
        fmt::print("frame {}: {} mm f/{:g} focus {:.3f} m, sensor {} mm, {} blades at {:g} deg\n", frame,
                   lens.focalLengthMm, lens.fNumber, lens.focusM, lens.sensorWidthMm, settings.aperture.blades,
                   lens.bladeRotationDeg);
        fs::create_directory(out);
        writeImageAtomically(fs::path(out) / "color.exr", images.frame.color);
        writeImageAtomically(fs::path(out) / "color.png", encodeSrgb(images.frame.color));
        writeImageAtomically(fs::path(out) / "depth.exr", images.frame.depth);
        if (!images.reference.empty()) {
            writeImageAtomically(fs::path(out) / "reference.exr", images.reference);
            writeImageAtomically(fs::path(out) / "reference.png", encodeSrgb(images.reference));
        }
        fmt::print("wrote {}/color.exr, depth.exr{} (+ PNG previews)\n", out,
                   images.reference.empty() ? "" : ", reference.exr");
        return kExitDone;
    } catch (const std::exception& error) {
        spdlog::error("{}", error.what());
        return bench::statusFor(error);
    }
}
