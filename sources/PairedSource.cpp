// SPDX-License-Identifier: LGPL-2.1-or-later
// Depth providers (fixed image, sequence on disk, live Z16 node) and the source that attaches
// their depth to each colour frame.
#include "sources/PairedSource.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string_view>
#include <system_error>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "filter/Log.hpp"

#include "sources/ImageIO.hpp"
#include "sources/PathNames.hpp"
#include "sources/TumLists.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

bool isDepthImage(const fs::path& file)
{
    const std::string ext = lowerExtension(file);
    return ext == ".png" || ext == ".tif" || ext == ".tiff" || ext == ".exr";
}

/// A file stem that is wholly a number ("1305031250.253735") as seconds.
std::optional<double> stemTime(const fs::path& file)
{
    const std::string stem = file.stem().string();
    double value = 0.0;
    const auto [end, error] = std::from_chars(stem.data(), stem.data() + stem.size(), value);
    if (error != std::errc() || end != stem.data() + stem.size() || !std::isfinite(value))
        return std::nullopt;
    return value;
}

double steadySeconds()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

} // namespace

// ---- StaticDepth ----

StaticDepth::StaticDepth(fs::path file, double unitsPerMetre)
    : file_(std::move(file)), depth_(readStoredDepth(file_, unitsPerMetre))
{
}

std::optional<DepthSample> StaticDepth::depthFor(const Frame&)
{
    return DepthSample{{depth_.image.clone(), depth_.unitsPerMetre}, file_.string()}; // each frame owns its pixels
}

std::string StaticDepth::describe() const
{
    return fmt::format("depth '{}' for every frame", file_.string());
}

// ---- DepthSequence ----

std::unique_ptr<DepthSequence> DepthSequence::fromFolder(const fs::path& folder, double unitsPerMetre,
                                                         DepthPairing pairing)
{
    std::vector<fs::path> files;
    std::error_code ec;
    for (const fs::directory_entry& entry : fs::directory_iterator(folder, ec)) {
        const fs::path& file = entry.path();
        if (entry.is_regular_file(ec) && isDepthImage(file) && !file.filename().string().starts_with("."))
            files.push_back(file);
    }
    if (ec)
        throw SourceError(fmt::format("cannot list depth folder '{}': {}", folder.string(), ec.message()));
    std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
        return naturalLess(a.filename().string(), b.filename().string());
    });
    std::vector<Entry> entries;
    bool timed = true;
    for (const fs::path& file : files) {
        entries.push_back({file, stemTime(file)});
        timed = timed && entries.back().time.has_value();
    }
    if (!timed) {
        if (pairing.mode == DepthPairing::Mode::Timestamp)
            throw SourceError(fmt::format("depth folder '{}': its file names are not times in seconds "
                                          "(e.g. 1305031250.253735.png), so it pairs by index only",
                                          folder.string()));
        for (Entry& entry : entries)
            entry.time.reset();
    }
    return std::make_unique<DepthSequence>(std::move(entries), unitsPerMetre, pairing,
                                           fmt::format("depth folder '{}'", folder.string()));
}

std::unique_ptr<DepthSequence> DepthSequence::fromList(const fs::path& list, double unitsPerMetre,
                                                       DepthPairing pairing)
{
    std::ifstream in(list);
    if (!in)
        throw SourceError(fmt::format("cannot read depth list '{}'", list.string()));
    const std::vector<tum::Listed> listed = tum::parseTimestampList(in, list);
    const fs::path folder = list.parent_path();
    std::vector<Entry> entries;
    std::error_code ec;
    for (const tum::Listed& item : listed) {
        const fs::path file = folder / item.file;
        if (!fs::is_regular_file(file, ec))
            throw SourceError(fmt::format("{}:{}: listed file '{}' does not exist", list.string(),
                                          item.line, file.string()));
        entries.push_back({file, item.time});
    }
    return std::make_unique<DepthSequence>(std::move(entries), unitsPerMetre, pairing,
                                           fmt::format("depth list '{}'", list.string()));
}

DepthSequence::DepthSequence(std::vector<Entry> entries, double unitsPerMetre, DepthPairing pairing,
                             std::string origin)
    : entries_(std::move(entries)), unitsPerMetre_(unitsPerMetre), pairing_(pairing),
      origin_(std::move(origin))
{
    if (entries_.empty())
        throw SourceError(fmt::format("{} holds no depth images", origin_));
    if (!(pairing_.maxGap >= 0.0))
        throw SourceError(fmt::format("{}: the pairing tolerance must be >= 0 s", origin_));
    if (pairing_.mode == DepthPairing::Mode::Timestamp) {
        for (const Entry& entry : entries_)
            if (!entry.time)
                throw SourceError(fmt::format("{}: '{}' has no time, so the sequence cannot pair by "
                                              "timestamp", origin_, entry.file.string()));
        std::stable_sort(entries_.begin(), entries_.end(),
                         [](const Entry& a, const Entry& b) { return *a.time < *b.time; });
    }
}

std::optional<std::size_t> DepthSequence::match(const Frame& color)
{
    if (pairing_.mode == DepthPairing::Mode::Index)
        return color.index < entries_.size() ? std::optional(color.index) : std::nullopt;

    double t = color.timestampS;
    if (pairing_.alignStarts) {
        if (!firstColorTime_)
            firstColorTime_ = t;
        t = t - *firstColorTime_ + *entries_.front().time;
    }
    const auto later = std::lower_bound(entries_.begin(), entries_.end(), t,
                                        [](const Entry& e, double time) { return *e.time < time; });
    std::optional<std::size_t> best;
    double bestGap = 0.0;
    const auto consider = [&](std::vector<Entry>::const_iterator it) {
        const double gap = std::abs(*it->time - t);
        if (!best || gap < bestGap) { // the earlier one is considered first and wins ties
            best = static_cast<std::size_t>(it - entries_.begin());
            bestGap = gap;
        }
    };
    if (later != entries_.begin())
        consider(std::prev(later));
    if (later != entries_.end())
        consider(later);
    // Times are printed with 6 decimals in TUM lists: allow 1 us of rounding.
    if (!best || bestGap > pairing_.maxGap + 1e-6)
        return std::nullopt;
    return best;
}

std::optional<DepthSample> DepthSequence::depthFor(const Frame& color)
{
    const std::optional<std::size_t> index = match(color);
    if (!index)
        return std::nullopt;
    if (cachedIndex_ != index) {
        cached_ = readStoredDepth(entries_[*index].file, unitsPerMetre_);
        cachedIndex_ = index;
    }
    return DepthSample{{cached_.image.clone(), cached_.unitsPerMetre}, entries_[*index].file.string()};
}

std::string DepthSequence::describe() const
{
    return pairing_.mode == DepthPairing::Mode::Index
               ? fmt::format("{} ({} images, paired by index)", origin_, entries_.size())
               : fmt::format("{} ({} images, paired by timestamp within {:.0f} ms)", origin_,
                             entries_.size(), pairing_.maxGap * 1000.0);
}

// ---- V4l2DepthStream ----

V4l2DepthStream::V4l2DepthStream(std::unique_ptr<V4l2Source> depth, double maxGap)
    : depth_(std::move(depth)),
      maxGap_(maxGap > 0.0 ? maxGap
                           : std::max(0.020, depth_->frameRate() > 0.0 ? 0.5 / depth_->frameRate() : 0.0)),
      lastArrival_(steadySeconds())
{
}

std::optional<DepthSample> V4l2DepthStream::depthFor(const Frame& color)
{
    using std::chrono::milliseconds;
    const double t = color.timestampS;
    const auto keep = [this](Frame frame) {
        recent_.push_back(std::move(frame));
        lastArrival_ = steadySeconds();
        while (recent_.size() > 16)
            recent_.pop_front();
    };
    // Everything already captured, then, while the newest depth is older than the colour frame,
    // what arrives within maxGap: a depth frame taken just after the colour frame may be nearer.
    while (std::optional<Frame> frame = depth_->nextWithin(milliseconds(0)))
        keep(std::move(*frame));
    const double waitUntil = steadySeconds() + maxGap_;
    while (recent_.empty() || recent_.back().timestampS < t) {
        const double left = waitUntil - steadySeconds();
        if (left <= 0.0)
            break;
        std::optional<Frame> frame = depth_->nextWithin(milliseconds(std::lround(std::ceil(left * 1000.0))));
        if (!frame)
            break;
        keep(std::move(*frame));
    }
    if (steadySeconds() - lastArrival_ > 5.0)
        throw SourceError(fmt::format("depth camera {} delivered no frame for 5 s (after {} frames)",
                                      depth_->device().string(), depth_->framesDelivered()));

    auto best = recent_.end();
    for (auto it = recent_.begin(); it != recent_.end(); ++it)
        if (best == recent_.end() || std::abs(it->timestampS - t) < std::abs(best->timestampS - t))
            best = it;
    if (best == recent_.end() || std::abs(best->timestampS - t) > maxGap_)
        return std::nullopt;
    DepthSample sample{{best->depth.clone(), best->depthScale}, best->name};
    recent_.erase(recent_.begin(), best); // older ones are no nearer to any later colour frame
    return sample;
}

std::string V4l2DepthStream::describe() const
{
    return fmt::format("{}, paired by timestamp within {:.0f} ms", depth_->describe(), maxGap_ * 1000.0);
}

// ---- PairedSource ----

PairedSource::PairedSource(std::unique_ptr<FrameSource> color, std::unique_ptr<DepthProvider> depth)
    : color_(std::move(color)), depth_(std::move(depth))
{
    const auto* sequence = dynamic_cast<const DepthSequence*>(depth_.get());
    const std::optional<std::size_t> colorCount = color_->frameCount();
    if (sequence && sequence->pairing().mode == DepthPairing::Mode::Index && colorCount &&
        *colorCount != *sequence->count())
        logger().warn("{} colour frames and {} depth images ({}): paired by index, {}", *colorCount,
                     *sequence->count(), depth_->describe(),
                     *colorCount > *sequence->count() ? "the frames past the last depth pass through in focus"
                                                      : "the extra depth images are not used");
}

std::optional<Frame> PairedSource::next()
{
    std::optional<Frame> frame = color_->next();
    if (!frame)
        return std::nullopt;
    std::optional<DepthSample> depth = depth_->depthFor(*frame);
    if (depth && !depth->depth.image.empty()) {
        if (const cv::Size size = colorSize(*frame); !size.empty())
            checkDepthFits(size, frame->name, depth->depth.image.size(), depth->name);
        frame->depth = std::move(depth->depth.image);
        frame->depthScale = depth->depth.unitsPerMetre;
    } else {
        frame->depth.release();
        if (unpaired_ == 0)
            logger().warn("{}: no depth pairs with colour frame {}; frames without depth pass through "
                         "in focus", depth_->describe(), frame->name);
        ++unpaired_;
    }
    return frame;
}

std::string PairedSource::describe() const
{
    return fmt::format("{} with {}", color_->describe(), depth_->describe());
}

} // namespace defocus
