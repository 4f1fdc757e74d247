// TUM RGB-D layout: parses rgb.txt / depth.txt / associations.txt, pairs colour with depth by
// timestamp when no associations are given, and reads the pairs in list order.
#include "sources/TumSource.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string_view>
#include <system_error>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "sources/ImageIO.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

/// One non-comment line of a list file, split at white space.
struct ListLine {
    std::size_t number = 0; // from 1
    std::string text;
    std::vector<std::string> tokens;
};

/// One "timestamp filename" entry of rgb.txt or depth.txt.
struct Listed {
    double time = 0.0;
    fs::path file;
    std::size_t line = 0;
};

std::vector<ListLine> readListFile(const fs::path& file)
{
    std::ifstream in(file);
    if (!in)
        throw SourceError(fmt::format("cannot open '{}'", file.string()));
    std::vector<ListLine> lines;
    std::string text;
    std::size_t number = 0;
    while (std::getline(in, text)) {
        ++number;
        if (!text.empty() && text.back() == '\r')
            text.pop_back();
        std::istringstream words(text);
        std::vector<std::string> tokens;
        for (std::string word; words >> word;)
            tokens.push_back(std::move(word));
        if (tokens.empty() || tokens.front().front() == '#')
            continue;
        lines.push_back({number, std::move(text), std::move(tokens)});
    }
    if (in.bad())
        throw SourceError(fmt::format("cannot read '{}'", file.string()));
    return lines;
}

std::optional<double> parseTime(const std::string& token)
{
    double value = 0.0;
    const char* end = token.data() + token.size();
    const auto [ptr, ec] = std::from_chars(token.data(), end, value);
    if (ec != std::errc() || ptr != end || !std::isfinite(value))
        return std::nullopt;
    return value;
}

[[noreturn]] void badLine(const fs::path& list, const ListLine& line, std::string_view expected)
{
    constexpr std::size_t shown = 60;
    std::string text = line.text.size() > shown ? line.text.substr(0, shown) + "..." : line.text;
    throw SourceError(
        fmt::format("{}:{}: expected '{}', got '{}'", list.string(), line.number, expected, text));
}

void requireFile(const fs::path& folder, const fs::path& list, std::size_t line,
                 const fs::path& listed)
{
    std::error_code ec;
    if (!fs::is_regular_file(folder / listed, ec))
        throw SourceError(fmt::format("{}:{}: listed file '{}' does not exist", list.string(), line,
                                      (folder / listed).string()));
}

std::vector<Listed> readTimestampList(const fs::path& list)
{
    std::vector<Listed> entries;
    for (const ListLine& line : readListFile(list)) {
        const std::optional<double> time =
            line.tokens.size() == 2 ? parseTime(line.tokens[0]) : std::nullopt;
        if (!time)
            badLine(list, line, "timestamp file");
        entries.push_back({*time, line.tokens[1], line.number});
    }
    return entries;
}

// The median frame interval finds dropped frames (gaps of 1.5 intervals or more); the rate is
// the mean over the other intervals. The median alone is biased by the capture clock's jitter:
// TUM fr1 steps of 31, 32 and 36 ms have a 32 ms median (31.2 Hz) for a 30 Hz camera.
double estimateFrameRate(std::vector<double> times)
{
    constexpr double fallback = 30.0;
    std::sort(times.begin(), times.end());
    std::vector<double> steps;
    for (std::size_t i = 1; i < times.size(); ++i)
        if (times[i] > times[i - 1])
            steps.push_back(times[i] - times[i - 1]);
    if (steps.empty())
        return fallback;
    std::vector<double> sorted = steps;
    const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
    std::nth_element(sorted.begin(), middle, sorted.end());
    const double median = *middle;
    double sum = 0.0;
    std::size_t count = 0;
    for (double step : steps)
        if (step < 1.5 * median) {
            sum += step;
            ++count;
        }
    return count > 0 && sum > 0.0 ? static_cast<double>(count) / sum : fallback;
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
    frameRate_ = estimateFrameRate(std::move(times));
}

void TumSource::readAssociations(const fs::path& list)
{
    pairing_ = "associations.txt";
    for (const ListLine& line : readListFile(list)) {
        const std::optional<double> rgbTime =
            line.tokens.size() == 4 ? parseTime(line.tokens[0]) : std::nullopt;
        const std::optional<double> depthTime =
            line.tokens.size() == 4 ? parseTime(line.tokens[2]) : std::nullopt;
        if (!rgbTime || !depthTime)
            badLine(list, line, "timestamp file timestamp file");
        requireFile(folder_, list, line.number, line.tokens[1]);
        requireFile(folder_, list, line.number, line.tokens[3]);
        entries_.push_back({*rgbTime, line.tokens[1], fs::path(line.tokens[3])});
    }
}

void TumSource::pairByTimestamp(const fs::path& rgbList, const fs::path& depthList)
{
    pairing_ = "nearest timestamp";
    const std::vector<Listed> rgb = readTimestampList(rgbList);
    std::vector<Listed> depth = readTimestampList(depthList);
    std::stable_sort(depth.begin(), depth.end(),
                     [](const Listed& a, const Listed& b) { return a.time < b.time; });

    // A microsecond of slack: the lists print six decimals, so a gap of exactly 20 ms may parse
    // as a hair more.
    constexpr double slack = 1e-6;
    std::size_t unpaired = 0;
    std::string firstUnpaired;
    for (const Listed& colour : rgb) {
        requireFile(folder_, rgbList, colour.line, colour.file);
        Entry entry{colour.time, colour.file, std::nullopt};
        const auto after = std::lower_bound(
            depth.begin(), depth.end(), colour.time,
            [](const Listed& d, double t) { return d.time < t; });
        const Listed* nearest = nullptr;
        if (after != depth.end())
            nearest = &*after;
        if (after != depth.begin()) {
            const Listed& before = *std::prev(after);
            if (!nearest || colour.time - before.time <= nearest->time - colour.time)
                nearest = &before;
        }
        if (nearest && std::abs(nearest->time - colour.time) <= maxPairingGap + slack) {
            requireFile(folder_, depthList, nearest->line, nearest->file);
            entry.depth = nearest->file;
        } else {
            if (unpaired++ == 0)
                firstUnpaired = colour.file.generic_string();
            spdlog::debug("{}: no depth within {} ms of {}", folder_.string(),
                          maxPairingGap * 1000.0, colour.file.generic_string());
        }
        entries_.push_back(std::move(entry));
    }
    if (unpaired > 0)
        spdlog::warn("TUM folder '{}': {} of {} colour frames have no depth within {} ms (first: "
                     "{}); they pass through in focus",
                     folder_.string(), unpaired, rgb.size(), maxPairingGap * 1000.0,
                     firstUnpaired);
}

std::optional<Frame> TumSource::next()
{
    if (next_ >= entries_.size())
        return std::nullopt;
    const Entry& entry = entries_[next_];
    Frame frame;
    frame.color = readColor(folder_ / entry.rgb);
    if (entry.depth)
        frame.depth = readDepth(folder_ / *entry.depth, unitsPerMetre_);
    frame.timestamp = entry.rgbTime;
    frame.index = next_;
    frame.name = entry.rgb.generic_string();
    ++next_;
    return frame;
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
