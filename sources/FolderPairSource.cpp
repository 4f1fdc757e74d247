// SPDX-License-Identifier: LGPL-2.1-or-later
// Folder pair source: lists the images of a colour folder (and a depth folder), sorts both by
// name and reads them pair by pair.
#include "sources/FolderPairSource.hpp"

#include <algorithm>
#include <array>
#include <string_view>
#include <system_error>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "filter/Log.hpp"

#include "sources/ImageIO.hpp"
#include "sources/PathNames.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

bool isImageFile(const fs::path& file)
{
    static constexpr std::array<std::string_view, 8> extensions = {
        ".png", ".jpg", ".jpeg", ".exr", ".tif", ".tiff", ".bmp", ".webp"};
    return std::find(extensions.begin(), extensions.end(), lowerExtension(file)) != extensions.end();
}

std::vector<fs::path> listImages(const fs::path& folder)
{
    std::vector<fs::path> files;
    try {
        for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
            const std::string name = entry.path().filename().string();
            if (name.empty() || name.front() == '.' || !entry.is_regular_file() ||
                !isImageFile(entry.path()))
                continue;
            files.push_back(entry.path());
        }
    } catch (const fs::filesystem_error& e) {
        throw SourceError(fmt::format("cannot list folder '{}': {}", folder.string(),
                                      e.code().message()));
    }
    std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
        return naturalLess(a.filename().string(), b.filename().string());
    });
    return files;
}

} // namespace

FolderPairSource::FolderPairSource(fs::path colorFolder, std::optional<fs::path> depth,
                                   double unitsPerMetre)
    : colorFolder_(std::move(colorFolder)), depth_(std::move(depth)),
      unitsPerMetre_(unitsPerMetre)
{
    colorFiles_ = listImages(colorFolder_);
    if (colorFiles_.empty())
        throw SourceError(fmt::format(
            "folder '{}' holds no images (png, jpg, jpeg, exr, tif, tiff, bmp or webp)",
            colorFolder_.string()));
    std::error_code ec;
    if (!depth_) {
        logger().warn("image folder '{}': no depth given; its {} frames pass through in focus",
                     colorFolder_.string(), colorFiles_.size());
    } else if (fs::is_directory(*depth_, ec)) {
        depthFiles_ = listImages(*depth_);
        if (depthFiles_.size() != colorFiles_.size())
            throw SourceError(fmt::format(
                "colour folder '{}' holds {} images but depth folder '{}' holds {}; they are "
                "paired one to one by sorted name",
                colorFolder_.string(), colorFiles_.size(), depth_->string(), depthFiles_.size()));
    } else {
        sharedDepth_ = readStoredDepth(*depth_, unitsPerMetre_);
    }
}

std::optional<Frame> FolderPairSource::next()
{
    const std::optional<Read> read = nextRead();
    return read ? (*read)() : std::nullopt;
}

std::optional<FrameSource::Read> FolderPairSource::nextRead()
{
    if (next_ >= colorFiles_.size())
        return std::nullopt;
    const std::size_t index = next_++;
    const std::optional<std::filesystem::path> depthFile =
        !depthFiles_.empty() ? std::optional(depthFiles_[index]) : depth_;
    // The one depth image for every frame is shared, read-only, with the reads (each frame gets
    // its own copy of the pixels).
    return [color = colorFiles_[index], depthFile, shared = sharedDepth_, perFrame = !depthFiles_.empty(), index,
            unitsPerMetre = unitsPerMetre_] {
        Frame frame;
        frame.color = readColor(color);
        StoredDepth depth;
        if (perFrame)
            depth = readStoredDepth(*depthFile, unitsPerMetre);
        else if (!shared.image.empty())
            depth = {shared.image.clone(), shared.unitsPerMetre};
        frame.depth = depth.image;
        frame.depthScale = depth.unitsPerMetre;
        if (!frame.depth.empty())
            checkDepthFits(frame.color.size(), color.string(), frame.depth.size(), depthFile->string());
        frame.index = index;
        frame.name = color.filename().string();
        return std::optional<Frame>(std::move(frame));
    };
}

std::optional<std::size_t> FolderPairSource::frameCount() const
{
    return colorFiles_.size();
}

std::string FolderPairSource::describe() const
{
    if (!depth_)
        return fmt::format("image folder '{}' ({} frames, no depth)", colorFolder_.string(),
                           colorFiles_.size());
    if (!depthFiles_.empty())
        return fmt::format("folder pair '{}' + '{}' ({} frames)", colorFolder_.string(),
                           depth_->string(), colorFiles_.size());
    return fmt::format("image folder '{}' ({} frames) + one depth image '{}'",
                       colorFolder_.string(), colorFiles_.size(), depth_->string());
}

} // namespace defocus
