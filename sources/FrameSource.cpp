// SPDX-License-Identifier: LGPL-2.1-or-later
// openSource: recognises what the input path names (TUM folder, image folder, image or video
// file) and opens the matching source.
#include "sources/FrameSource.hpp"

#include <cmath>
#include <system_error>

#include <fmt/format.h>

#include "filter/Log.hpp"
#include "sources/FolderPairSource.hpp"
#include "sources/PathNames.hpp"
#include "sources/SingleImageSource.hpp"
#include "sources/StreamSources.hpp" // cameras and video files
#include "sources/TumSource.hpp"
#include "sources/VideoFileSource.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

/// Units per metre of 16-bit depth when the options do not say: TUM publishes depth in
/// 1/5000 m; most other tools (Kinect SDK, RealSense, Blender's 16-bit export) use millimetres.
constexpr double tumUnitsPerMetre = 5000.0;
constexpr double defaultUnitsPerMetre = 1000.0;

} // namespace

double defaultDepthScale(const SourceOptions& options)
{
    std::error_code ec;
    const fs::path& input = options.input;
    if (fs::is_directory(input, ec) && (fs::exists(input / "rgb.txt", ec) || fs::exists(input / "associations.txt", ec)))
        return tumUnitsPerMetre;
    if (options.depth && lowerExtension(*options.depth) == ".txt")
        return tumUnitsPerMetre;
    return defaultUnitsPerMetre;
}

std::optional<FrameSource::Read> FrameSource::nextRead()
{
    std::optional<Frame> frame = next();
    if (!frame)
        return std::nullopt;
    return [frame = std::move(*frame)] { return std::optional<Frame>(frame); };
}

namespace {

/// A source's frames with their depth in metres (depthMetres()).
class MetresSource final : public FrameSource {
public:
    explicit MetresSource(std::unique_ptr<FrameSource> source) : source_(std::move(source)) {}
    std::optional<Frame> next() override { return inMetres(source_->next()); }
    std::optional<Read> nextRead() override
    {
        std::optional<Read> read = source_->nextRead();
        if (!read)
            return std::nullopt;
        return [read = std::move(*read)] { return inMetres(read()); };
    }
    std::optional<std::size_t> frameCount() const override { return source_->frameCount(); }
    double frameRate() const override { return source_->frameRate(); }
    std::string describe() const override { return source_->describe(); }
    bool isLive() const override { return source_->isLive(); }

private:
    static std::optional<Frame> inMetres(std::optional<Frame> frame)
    {
        if (frame && frame->depthScale > 0.0) {
            frame->depth = depthMetres(*frame);
            frame->depthScale = 0.0;
        }
        return frame;
    }

    std::unique_ptr<FrameSource> source_;
};

/// openSource() with the depth as stored.
std::unique_ptr<FrameSource> openStoredSource(const SourceOptions& options)
{
    const fs::path& input = options.input;
    if (input.empty())
        throw SourceError("no input given");
    std::error_code ec;
    if (!fs::exists(input, ec))
        throw SourceError(fmt::format("input '{}' does not exist", input.string()));
    if (options.depth && !fs::exists(*options.depth, ec))
        throw SourceError(fmt::format("depth '{}' does not exist", options.depth->string()));
    if (options.depthScale && !(*options.depthScale > 0.0 && std::isfinite(*options.depthScale)))
        throw SourceError(fmt::format(
            "depth scale must be a positive number of units per metre, got {}",
            *options.depthScale));
    // ---- streams: cameras, and video files with a depth sequence ----
    if (std::unique_ptr<FrameSource> stream = openStreamSource(options))
        return stream;

    if (fs::is_directory(input, ec)) {
        if (fs::exists(input / "rgb.txt", ec) || fs::exists(input / "associations.txt", ec)) {
            if (options.depth)
                throw SourceError(fmt::format(
                    "input '{}' is a TUM folder, which names its own depth files; drop the "
                    "depth '{}'",
                    input.string(), options.depth->string()));
            return std::make_unique<TumSource>(input, options.depthScale.value_or(tumUnitsPerMetre));
        }
        return std::make_unique<FolderPairSource>(
            input, options.depth, options.depthScale.value_or(defaultUnitsPerMetre));
    }
    if (fs::is_regular_file(input, ec)) {
        const double scale = options.depthScale.value_or(defaultUnitsPerMetre);
        if (isVideoFile(input)) {
            if (!options.depth) // a depth folder or depth.txt went to openStreamSource
                logger().warn("video '{}': no depth given; its frames pass through in focus", input.string());
            return std::make_unique<VideoFileSource>(input, options.depth, scale);
        }
        if (options.depth && fs::is_directory(*options.depth, ec))
            throw SourceError(fmt::format(
                "input '{}' is one image but depth '{}' is a folder; give one depth image",
                input.string(), options.depth->string()));
        return std::make_unique<SingleImageSource>(input, options.depth, scale);
    }
    throw SourceError(
        fmt::format("input '{}' is neither a folder nor a regular file", input.string()));
}

} // namespace

std::unique_ptr<FrameSource> openSource(const SourceOptions& options)
{
    std::unique_ptr<FrameSource> source = openStoredSource(options);
    if (options.depthUnits)
        return source;
    return std::make_unique<MetresSource>(std::move(source));
}

} // namespace defocus
