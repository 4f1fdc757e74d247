// SPDX-License-Identifier: LGPL-2.1-or-later
// TUM list files: line splitting, timestamp parsing, nearest-timestamp pairing and the frame rate
// estimate, kept free of file access so that they can be fuzzed from memory.
#include "sources/TumLists.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numeric>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include <fmt/format.h>

#include "sources/FrameSource.hpp"

namespace defocus::tum {
namespace {

namespace fs = std::filesystem;

/// One non-comment line of a list file, split at white space.
struct ListLine {
    std::size_t number = 0; // from 1
    std::string text;
    std::vector<std::string> tokens;
};

std::vector<ListLine> readListLines(std::istream& in, const fs::path& name)
{
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
        throw SourceError(fmt::format("cannot read '{}'", name.string()));
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

// Control characters (a binary file read as a list) are shown as '?', so the message stays one
// printable line.
[[noreturn]] void badLine(const fs::path& name, const ListLine& line, std::string_view expected)
{
    constexpr std::size_t shown = 60;
    std::string text = line.text.size() > shown ? line.text.substr(0, shown) + "..." : line.text;
    std::replace_if(
        text.begin(), text.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }, '?');
    throw SourceError(fmt::format("{}:{}: expected '{}', got '{}'", name.string(), line.number, expected, text));
}

} // namespace

std::vector<Listed> parseTimestampList(std::istream& in, const fs::path& name)
{
    std::vector<Listed> entries;
    for (const ListLine& line : readListLines(in, name)) {
        const std::optional<double> time = line.tokens.size() == 2 ? parseTime(line.tokens[0]) : std::nullopt;
        if (!time)
            badLine(name, line, "timestamp file");
        entries.push_back({*time, line.tokens[1], line.number});
    }
    return entries;
}

std::vector<Association> parseAssociations(std::istream& in, const fs::path& name)
{
    std::vector<Association> entries;
    for (const ListLine& line : readListLines(in, name)) {
        const bool four = line.tokens.size() == 4;
        const std::optional<double> rgbTime = four ? parseTime(line.tokens[0]) : std::nullopt;
        const std::optional<double> depthTime = four ? parseTime(line.tokens[2]) : std::nullopt;
        if (!rgbTime || !depthTime)
            badLine(name, line, "timestamp file timestamp file");
        entries.push_back({{*rgbTime, line.tokens[1], line.number}, {*depthTime, line.tokens[3], line.number}});
    }
    return entries;
}

std::vector<std::optional<std::size_t>> pairByTimestamp(const std::vector<Listed>& rgb,
                                                        const std::vector<Listed>& depth, double maxGap)
{
    // A microsecond of slack: the lists print six decimals, so a gap of exactly 20 ms may parse
    // as a hair more.
    constexpr double slack = 1e-6;
    std::vector<std::size_t> byTime(depth.size());
    std::iota(byTime.begin(), byTime.end(), std::size_t{0});
    std::stable_sort(byTime.begin(), byTime.end(),
                     [&](std::size_t a, std::size_t b) { return depth[a].time < depth[b].time; });

    std::vector<std::optional<std::size_t>> pairs;
    pairs.reserve(rgb.size());
    for (const Listed& colour : rgb) {
        const auto after = std::lower_bound(byTime.begin(), byTime.end(), colour.time,
                                            [&](std::size_t d, double t) { return depth[d].time < t; });
        std::optional<std::size_t> nearest;
        if (after != byTime.end())
            nearest = *after;
        if (after != byTime.begin()) {
            const std::size_t before = *std::prev(after);
            if (!nearest || colour.time - depth[before].time <= depth[*nearest].time - colour.time)
                nearest = before;
        }
        if (nearest && !(std::abs(depth[*nearest].time - colour.time) <= maxGap + slack))
            nearest.reset();
        pairs.push_back(nearest);
    }
    return pairs;
}

// The median frame interval finds dropped frames (gaps of 1.5 intervals or more); the rate is
// the mean over the other intervals. The median alone is biased by the capture clock's jitter:
// TUM fr1 steps of 31, 32 and 36 ms have a 32 ms median (31.2 Hz) for a 30 Hz camera.
double estimateFrameRate(std::vector<double> times)
{
    constexpr double fallback = 30.0;
    std::erase_if(times, [](double t) { return !std::isfinite(t); }); // NaN would break the sort
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
    if (count == 0)
        return fallback;
    const double rate = static_cast<double>(count) / sum;
    return rate >= kMinFrameRate && rate <= kMaxFrameRate ? rate : fallback;
}

} // namespace defocus::tum
