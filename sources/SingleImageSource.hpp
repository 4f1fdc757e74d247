// SPDX-License-Identifier: LGPL-2.1-or-later
// One colour image file, with an optional depth image file: a clip of one frame.
//   defocus photo.png --depth depth.png -o out.png
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include "sources/FrameSource.hpp"

namespace defocus {

class SingleImageSource final : public FrameSource {
public:
    /// Reads both files at once, so that a bad file fails before any output. Without `depthFile`
    /// the frame has no depth and passes through in focus (logged as a warning). Throws
    /// SourceError for an unreadable file or a depth of another aspect ratio than the colour.
    SingleImageSource(std::filesystem::path colorFile,
                      std::optional<std::filesystem::path> depthFile, double unitsPerMetre);

    std::optional<Frame> next() override;
    std::optional<std::size_t> frameCount() const override { return 1; }
    std::string describe() const override { return description_; }

private:
    Frame frame_;
    bool delivered_ = false;
    std::string description_;
};

} // namespace defocus
