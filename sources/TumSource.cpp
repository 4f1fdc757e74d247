// SPDX-License-Identifier: LGPL-2.1-or-later
// TUM RGB-D layout: parses rgb.txt / depth.txt / associations.txt, pairs colour with depth by
// timestamp when no associations are given, and reads the pairs in list order.
#include "sources/TumSource.hpp"

#include <algorithm>
#include <fstream>
#include <system_error>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "filter/Log.hpp"

#include "sources/ImageIO.hpp"
#include "sources/TumLists.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

std::ifstream openList(const fs::path& file)
{
    std::ifstream in(file);
    if (!in)
        throw SourceError(fmt::format("cannot open '{}'", file.string()));
    return in;
}

void requireFile(const fs::path& folder, const fs::path& list, std::size_t line,
                 const fs::path& listed)
{
    std::error_code ec;
    if (!fs::is_regular_file(folder / listed, ec))
        throw SourceError(fmt::format("{}:{}: listed file '{}' {}", list.string(), line,
                                      (folder / listed).string(),
                                      fs::exists(folder / listed, ec) ? "is not a regular file"
                                                                      : "does not exist"));
}

} // namespace

TumSource::TumSource(fs::path folder, double unitsPerMetre)
    : folder_(std::move(folder)), unitsPerMetre_(unitsPerMetre)
{
    const fs::path associations = folder_ / "associations.txt";
    const fs::path rgbList = folder_ / "rgb.txt";
    const fs::path depthList = folder_ / "depth.txt";
    std::error_code ec;
    if (fs::exists(associations, ec)) {
        readAssociations(associations);
    } else {
        if (!fs::exists(rgbList, ec))
            throw SourceError(fmt::format("TUM folder '{}' has no rgb.txt", folder_.string()));
        if (!fs::exists(depthList, ec))
            throw SourceError(fmt::format(
                "TUM folder '{}' has rgb.txt but neither depth.txt nor associations.txt",
                folder_.string()));
        pairByTimestamp(rgbList, depthList);
    }
    if (entries_.empty())
        throw SourceError(fmt::format("TUM folder '{}': {} lists no frames", folder_.string(),
                                      pairing_ == "associations.txt" ? "associations.txt"
                                                                     : "rgb.txt"));
    std::vector<double> times;
    for (const Entry& e : entries_)
        times.push_back(e.rgbTime);
    frameRate_ = tum::estimateFrameRate(std::move(times));
}

void TumSource::readAssociations(const fs::path& list)
{
    pairing_ = "associations.txt";
    std::ifstream in = openList(list);
    for (const tum::Association& a : tum::parseAssociations(in, list)) {
        requireFile(folder_, list, a.rgb.line, a.rgb.file);
        requireFile(folder_, list, a.depth.line, a.depth.file);
        entries_.push_back({a.rgb.time, a.rgb.file, a.depth.file});
    }
}

void TumSource::pairByTimestamp(const fs::path& rgbList, const fs::path& depthList)
{
    pairing_ = "nearest timestamp";
    std::ifstream rgbIn = openList(rgbList);
    const std::vector<tum::Listed> rgb = tum::parseTimestampList(rgbIn, rgbList);
    std::ifstream depthIn = openList(depthList);
    const std::vector<tum::Listed> depth = tum::parseTimestampList(depthIn, depthList);
    const std::vector<std::optional<std::size_t>> pairs = tum::pairByTimestamp(rgb, depth, maxPairingGap);

    std::size_t unpaired = 0;
    std::string firstUnpaired;
    for (std::size_t i = 0; i < rgb.size(); ++i) {
        const tum::Listed& colour = rgb[i];
        requireFile(folder_, rgbList, colour.line, colour.file);
        Entry entry{colour.time, colour.file, std::nullopt};
        if (pairs[i]) {
            const tum::Listed& paired = depth[*pairs[i]];
            requireFile(folder_, depthList, paired.line, paired.file);
            entry.depth = paired.file;
        } else {
            if (unpaired++ == 0)
                firstUnpaired = colour.file.generic_string();
            logger().debug("{}: no depth within {} ms of {}", folder_.string(),
                          maxPairingGap * 1000.0, colour.file.generic_string());
        }
        entries_.push_back(std::move(entry));
    }
    if (unpaired > 0)
        logger().warn("TUM folder '{}': {} of {} colour frames have no depth within {} ms (first: "
                     "{}); they pass through in focus",
                     folder_.string(), unpaired, rgb.size(), maxPairingGap * 1000.0,
                     firstUnpaired);
}

std::optional<Frame> TumSource::next()
{
    const std::optional<Read> read = nextRead();
    return read ? (*read)() : std::nullopt;
}

std::optional<FrameSource::Read> TumSource::nextRead()
{
    if (next_ >= entries_.size())
        return std::nullopt;
    const std::size_t index = next_++;
    return [entry = entries_[index], index, folder = folder_, unitsPerMetre = unitsPerMetre_] {
        Frame frame;
        frame.color = readColor(folder / entry.rgb);
        if (entry.depth) {
            StoredDepth depth = readStoredDepth(folder / *entry.depth, unitsPerMetre);
            frame.depth = depth.image;
            frame.depthScale = depth.unitsPerMetre;
            checkDepthFits(frame.color.size(), (folder / entry.rgb).string(), frame.depth.size(),
                           (folder / *entry.depth).string());
        }
        frame.timestampS = entry.rgbTime;
        frame.index = index;
        frame.name = entry.rgb.generic_string();
        return std::optional<Frame>(std::move(frame));
    };
}

std::optional<std::size_t> TumSource::frameCount() const
{
    return entries_.size();
}

double TumSource::frameRate() const
{
    return frameRate_;
}

std::string TumSource::describe() const
{
    const auto withDepth = static_cast<std::size_t>(std::count_if(
        entries_.begin(), entries_.end(), [](const Entry& e) { return e.depth.has_value(); }));
    return fmt::format("TUM RGB-D sequence '{}' ({} frames, {} with depth, paired by {}, {:.3g} Hz)",
                       folder_.string(), entries_.size(), withDepth, pairing_, frameRate_);
}

} // namespace defocus
