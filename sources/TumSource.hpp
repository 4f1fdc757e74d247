// SPDX-License-Identifier: LGPL-2.1-or-later
// Reads the TUM RGB-D benchmark layout: a folder with rgb.txt and depth.txt (paired by nearest
// timestamp) or associations.txt (pairs given).   defocus data/tum_fr1_rpy -o out.mp4
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "sources/FrameSource.hpp"

namespace defocus {

class TumSource final : public FrameSource {
public:
    /// A colour and a depth frame further apart than this are not paired, in seconds (the
    /// benchmark's own associate.py uses the same 20 ms).
    static constexpr double maxPairingGap = 0.020;

    /// Parses the list files and checks that every file they name exists, so that errors come
    /// before any output. `unitsPerMetre`: scale of the 16-bit depth PNGs (TUM uses 5000).
    /// Throws SourceError naming the list file and line.
    TumSource(std::filesystem::path folder, double unitsPerMetre);

    /// Throws SourceError naming the file for an unreadable image, or both files for a depth of
    /// another aspect ratio than its colour.
    std::optional<Frame> next() override;
    /// Each frame's files read and decoded on the thread that runs the read.
    std::optional<Read> nextRead() override;
    std::optional<std::size_t> frameCount() const override;
    double frameRate() const override;
    std::string describe() const override;

private:
    struct Entry {
        double rgbTime = 0.0;
        std::filesystem::path rgb; // relative to the folder, as listed
        std::optional<std::filesystem::path> depth;
    };

    void readAssociations(const std::filesystem::path& list);
    void pairByTimestamp(const std::filesystem::path& rgbList,
                         const std::filesystem::path& depthList);

    std::filesystem::path folder_;
    double unitsPerMetre_;
    std::vector<Entry> entries_;
    std::string pairing_;
    double frameRate_ = 30.0;
    std::size_t next_ = 0;
};

} // namespace defocus
