// SPDX-License-Identifier: LGPL-2.1-or-later
// Opens cameras and pairs colour with depth from another source, by what the paths name.
#include "sources/StreamSources.hpp"

#include <cmath>
#include <string>
#include <system_error>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "filter/Log.hpp"

#include "sources/PairedSource.hpp"
#include "sources/PathNames.hpp"
#include "sources/V4l2Source.hpp"
#include "sources/VideoFileSource.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

/// 16-bit depth units per metre when --depth-scale is not given: TUM lists (depth.txt) are in
/// 1/5000 m, everything else (RealSense, Kinect SDK, Blender's 16-bit export) in millimetres.
constexpr double tumUnitsPerMetre = 5000.0;
constexpr double defaultUnitsPerMetre = 1000.0;

bool isDepthSequence(const fs::path& depth)
{
    std::error_code ec;
    return fs::is_directory(depth, ec) || lowerExtension(depth) == ".txt";
}

/// A depth image, folder or list on disk, paired by index.
std::unique_ptr<DepthProvider> depthFromFiles(const fs::path& depth, std::optional<double> scale)
{
    std::error_code ec;
    if (fs::is_directory(depth, ec))
        return DepthSequence::fromFolder(depth, scale.value_or(defaultUnitsPerMetre), {});
    if (lowerExtension(depth) == ".txt")
        return DepthSequence::fromList(depth, scale.value_or(tumUnitsPerMetre), {});
    return std::make_unique<StaticDepth>(depth, scale.value_or(defaultUnitsPerMetre));
}

} // namespace

std::unique_ptr<FrameSource> openStreamSource(const SourceOptions& options)
{
    const bool cameraInput = isCameraPath(options.input);
    const bool cameraDepth = options.depth && isCameraPath(*options.depth);
    if (cameraDepth && !cameraInput)
        throw SourceError(fmt::format(
            "depth '{}' is a camera, which pairs with a colour camera only (defocus /dev/video0 "
            "--depth /dev/video2); give '{}' a depth image, folder or depth.txt",
            options.depth->string(), options.input.string()));

    if (cameraInput) {
        if (options.width <= 0 || options.height <= 0 || !(options.fps > 0.0 && std::isfinite(options.fps)))
            throw SourceError(fmt::format("camera {}: size and frame rate must be positive, got {}x{} "
                                          "at {} Hz", options.input.string(), options.width,
                                          options.height, options.fps));
        V4l2Options colour;
        colour.device = options.input;
        colour.width = options.width;
        colour.height = options.height;
        colour.fps = options.fps;
        colour.pixelFormat = options.pixelFormat;
        colour.yuvColor = options.yuvColor;
        auto camera = std::make_unique<V4l2Source>(colour);
        if (!options.depth) {
            logger().warn("camera {}: no depth given; its frames pass through in focus",
                         options.input.string());
            return camera;
        }
        if (cameraDepth) {
            V4l2Options depth = colour;
            depth.device = *options.depth;
            depth.role = V4l2Options::Role::Depth;
            depth.pixelFormat.clear(); // the depth camera's own Z16
            depth.unitsPerMetre = options.depthScale.value_or(defaultUnitsPerMetre);
            return std::make_unique<PairedSource>(
                std::move(camera),
                std::make_unique<V4l2DepthStream>(std::make_unique<V4l2Source>(depth)));
        }
        return std::make_unique<PairedSource>(std::move(camera),
                                              depthFromFiles(*options.depth, options.depthScale));
    }

    std::error_code ec;
    if (options.depth && isDepthSequence(*options.depth) && isVideoFile(options.input) &&
        fs::is_regular_file(options.input, ec))
        return std::make_unique<PairedSource>(
            std::make_unique<VideoFileSource>(options.input, std::nullopt,
                                              options.depthScale.value_or(defaultUnitsPerMetre)),
            depthFromFiles(*options.depth, options.depthScale));
    return nullptr;
}

} // namespace defocus
