// SPDX-License-Identifier: LGPL-2.1-or-later
// Single image source: reads one colour file and its depth file up front, then yields one frame.
#include "sources/SingleImageSource.hpp"

#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "filter/Log.hpp"

#include "sources/ImageIO.hpp"

namespace defocus {

SingleImageSource::SingleImageSource(std::filesystem::path colorFile,
                                     std::optional<std::filesystem::path> depthFile,
                                     double unitsPerMetre)
{
    frame_.color = readColor(colorFile);
    frame_.name = colorFile.filename().string();
    if (depthFile) {
        StoredDepth depth = readStoredDepth(*depthFile, unitsPerMetre);
        frame_.depth = depth.image;
        frame_.depthScale = depth.unitsPerMetre;
        checkDepthFits(frame_.color.size(), colorFile.string(), frame_.depth.size(),
                       depthFile->string());
        description_ = fmt::format("image '{}' + depth '{}'", colorFile.string(),
                                   depthFile->string());
    } else {
        logger().warn("image '{}': no depth given; it passes through in focus", colorFile.string());
        description_ = fmt::format("image '{}' (no depth)", colorFile.string());
    }
}

std::optional<Frame> SingleImageSource::next()
{
    if (delivered_)
        return std::nullopt;
    delivered_ = true;
    return std::move(frame_);
}

} // namespace defocus
