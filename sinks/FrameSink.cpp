// openSink: picks the sink from the output path (folder/, video container, image file or
// /dev/video* virtual camera).
#include "sinks/FrameSink.hpp"

#include <algorithm>
#include <cctype>
#include <system_error>

#include <fmt/format.h>

#include "sinks/ImageSinks.hpp"
#include "sinks/V4l2OutputSink.hpp"
#include "sinks/VideoSink.hpp"

namespace defocus {

std::unique_ptr<FrameSink> openSink(const SinkOptions& options)
{
    namespace fs = std::filesystem;
    const fs::path& output = options.output;
    if (output.empty())
        throw SinkError("no output given");
    const std::string& text = output.native();
    if (isV4l2DevicePath(output))
        return std::make_unique<V4l2OutputSink>(output, options.fps);
    std::error_code ec;
    if (text.back() == '/' || fs::is_directory(output, ec))
        return std::make_unique<ImageSequenceSink>(output, options.linearSequence);

    std::string ext = output.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".mp4" || ext == ".mkv" || ext == ".avi")
        return std::make_unique<VideoSink>(output, options.fps);
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".exr")
        return std::make_unique<SingleImageSink>(output);
    if (ext.empty())
        throw SinkError(fmt::format("output '{}' has no extension: end it with '/' for an image "
                                    "sequence, or use .mp4, .mkv, .avi, .png, .jpg or .exr",
                                    output.string()));
    throw SinkError(fmt::format("output '{}': unknown extension '{}' (use a folder/, .mp4, .mkv, "
                                ".avi, .png, .jpg or .exr)",
                                output.string(), ext));
}

} // namespace defocus
