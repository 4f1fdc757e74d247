// SPDX-License-Identifier: LGPL-2.1-or-later
// openSink: picks the sink from the output path (folder/, video container, image file or
// /dev/video* virtual camera).
#include "sinks/FrameSink.hpp"

#include <fstream>
#include <system_error>

#include <unistd.h>

#include <fmt/format.h>

#include "sinks/ImageSinks.hpp"
#include "sinks/V4l2OutputSink.hpp"
#include "sinks/VideoSink.hpp"
#include "sources/PathNames.hpp"

namespace defocus {

namespace fs = std::filesystem;

void refuseExisting(const fs::path& file, bool overwrite)
{
    std::error_code ec;
    if (overwrite || !fs::exists(file, ec))
        return;
    if (fs::is_directory(file, ec)) {
        if (fs::is_empty(file, ec))
            return;
        throw SinkError(fmt::format("output folder '{}' is not empty (-y writes into it, replacing its frames)",
                                    file.string()));
    }
    throw SinkError(fmt::format("output '{}' exists (-y overwrites it)", file.string()));
}

void requireParentFolder(const fs::path& output, bool isFolder)
{
    fs::path path = output;
    if (isFolder && !path.has_filename())
        path = path.parent_path(); // out/frames/ -> out/frames
    const fs::path parent = path.parent_path();
    std::error_code ec;
    if (parent.empty() || fs::is_directory(parent, ec))
        return;
    throw SinkError(fmt::format("cannot write '{}': folder '{}' does not exist", output.string(), parent.string()));
}

namespace {

/// `output` without a trailing '/': "out/" -> "out".
fs::path withoutSlash(const fs::path& output)
{
    return output.has_filename() ? output : output.parent_path();
}

} // namespace

fs::path partialPath(const fs::path& output, bool folder)
{
    const fs::path path = withoutSlash(output);
    if (folder)
        return path.parent_path() / (path.filename().string() + ".partial");
    return path.parent_path() / (path.stem().string() + ".partial" + path.extension().string());
}

fs::path temporaryPath(const fs::path& output, bool folder)
{
    const fs::path partial = partialPath(output, folder);
    return partial.parent_path() / fmt::format(".{}", partial.filename().string());
}

fs::path keepOrRemove(const fs::path& temporary, const fs::path& output, bool folder, bool keep, std::size_t written,
                      std::string_view what)
{
    std::error_code ec;
    if (!keep || written == 0) {
        fs::remove_all(temporary, ec);
        return {};
    }
    const fs::path kept = partialPath(output, folder);
    if (folder)
        fs::remove_all(kept, ec); // an earlier run's: a rename does not replace a folder
    fs::rename(temporary, kept, ec);
    if (ec) {
        const std::string why = ec.message();
        if (!folder)
            fs::remove(temporary, ec);
        throw SinkError(fmt::format("cannot keep the partial {} '{}': {}", what, kept.string(), why));
    }
    return kept;
}

void writeFileAtomically(const fs::path& file, const std::string& contents)
{
    const fs::path partial =
        file.parent_path() / fmt::format(".{}.partial-{}", file.filename().string(), ::getpid());
    std::error_code ec;
    {
        std::ofstream out(partial, std::ios::binary);
        out << contents;
        out.flush();
        if (!out) {
            fs::remove(partial, ec);
            throw SinkError(fmt::format("cannot write '{}'", file.string()));
        }
    }
    fs::rename(partial, file, ec);
    if (ec) {
        fs::remove(partial, ec);
        throw SinkError(fmt::format("cannot write '{}': {}", file.string(), ec.message()));
    }
}

std::unique_ptr<FrameSink> openSink(const SinkOptions& options)
{
    const fs::path& output = options.output;
    if (output.empty())
        throw SinkError("no output given");
    const std::string& text = output.native();
    if (isV4l2DevicePath(output))
        return std::make_unique<V4l2OutputSink>(output, options.fps);
    std::error_code ec;
    if (text.back() == '/' || fs::is_directory(output, ec)) {
        requireParentFolder(output, true);
        refuseExisting(output, options.overwrite);
        return std::make_unique<ImageSequenceSink>(output, options.linearSequence, options.fps, options.threads);
    }
    requireParentFolder(output, false);
    refuseExisting(output, options.overwrite);

    const std::string ext = lowerExtension(output);
    if (ext == ".mp4" || ext == ".mkv" || ext == ".webm" || ext == ".avi")
        return std::make_unique<VideoSink>(output, options.fps, options.codec);
    if (!options.codec.empty())
        throw SinkError(fmt::format("output '{}': --codec {} is for video outputs (.mp4, .mkv, .webm, .avi)",
                                    output.string(), options.codec));
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".exr")
        return std::make_unique<SingleImageSink>(output);
    if (ext.empty())
        throw SinkError(fmt::format("output '{}' has no extension: end it with '/' for an image "
                                    "sequence, or use .mp4, .mkv, .webm, .avi, .png, .jpg or .exr",
                                    output.string()));
    throw SinkError(fmt::format("output '{}': unknown extension '{}' (use a folder/, .mp4, .mkv, "
                                ".webm, .avi, .png, .jpg or .exr)",
                                output.string(), ext));
}

} // namespace defocus
