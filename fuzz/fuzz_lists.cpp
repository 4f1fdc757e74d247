// SPDX-License-Identifier: LGPL-2.1-or-later
// Fuzzes the TUM list parsers and the timestamp pairing from memory. The input is rgb.txt, a NUL
// byte, then depth.txt; the whole input is also parsed as associations.txt. Any text either
// parses or throws SourceError naming LIST:LINE; what parses obeys the documented invariants.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz/FuzzSupport.hpp"
#include "sources/FrameSource.hpp"
#include "sources/TumLists.hpp"

namespace {

using namespace defocus;

constexpr double maxGap = 0.020;

// A SourceError must name the list and a line that exists: "NAME:LINE: expected ...".
void checkMessage(const SourceError& error, std::string_view name, std::string_view text)
{
    const std::string message = error.what();
    FUZZ_CHECK(message.rfind(std::string(name) + ":", 0) == 0, "message does not start with the list name: %s",
               message.c_str());
    const std::size_t lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
    const std::size_t line = std::stoul(message.substr(name.size() + 1));
    FUZZ_CHECK(line >= 1 && line <= lines, "line %zu of %zu lines: %s", line, lines, message.c_str());
    FUZZ_CHECK(message.find('\n') == std::string::npos && message.find('\r') == std::string::npos,
               "message is not one line: %s", message.c_str());
}

void checkListed(const std::vector<tum::Listed>& entries)
{
    std::size_t previousLine = 0;
    for (const tum::Listed& e : entries) {
        FUZZ_CHECK(std::isfinite(e.time), "non-finite time on line %zu", e.line);
        FUZZ_CHECK(!e.file.empty(), "empty file name on line %zu", e.line);
        FUZZ_CHECK(e.line > previousLine, "line %zu after line %zu", e.line, previousLine);
        previousLine = e.line;
    }
}

std::vector<tum::Listed> parseList(std::string_view text, const char* name)
{
    std::istringstream in{std::string(text)};
    try {
        std::vector<tum::Listed> entries = tum::parseTimestampList(in, name);
        checkListed(entries);
        return entries;
    } catch (const SourceError& e) {
        checkMessage(e, name, text);
        return {};
    }
}

void checkPairing(const std::vector<tum::Listed>& rgb, const std::vector<tum::Listed>& depth)
{
    const std::vector<std::optional<std::size_t>> pairs = tum::pairByTimestamp(rgb, depth, maxGap);
    FUZZ_CHECK(pairs.size() == rgb.size(), "%zu pairs for %zu colour frames", pairs.size(), rgb.size());
    const bool bruteForce = rgb.size() * depth.size() <= 20000;
    for (std::size_t i = 0; i < rgb.size(); ++i) {
        double best = INFINITY;
        if (bruteForce)
            for (const tum::Listed& d : depth)
                best = std::min(best, std::abs(d.time - rgb[i].time));
        if (!pairs[i]) {
            FUZZ_CHECK(!bruteForce || !(best <= maxGap), "frame %zu unpaired with depth %g s away", i, best);
            continue;
        }
        FUZZ_CHECK(*pairs[i] < depth.size(), "depth index %zu of %zu", *pairs[i], depth.size());
        const double gap = std::abs(depth[*pairs[i]].time - rgb[i].time);
        FUZZ_CHECK(gap <= maxGap + 1e-6, "frame %zu paired %g s away", i, gap);
        FUZZ_CHECK(!bruteForce || gap == best, "frame %zu paired %g s away, nearest is %g s", i, gap, best);
    }
}

void checkFrameRate(const std::vector<tum::Listed>& entries)
{
    std::vector<double> times;
    for (const tum::Listed& e : entries)
        times.push_back(e.time);
    const double rate = tum::estimateFrameRate(times);
    FUZZ_CHECK(rate == 30.0 || (rate >= tum::kMinFrameRate && rate <= tum::kMaxFrameRate), "frame rate %g", rate);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    const std::size_t split = input.find('\0');
    const std::string_view rgbText = input.substr(0, split);
    const std::string_view depthText = split == std::string_view::npos ? std::string_view() : input.substr(split + 1);

    const std::vector<tum::Listed> rgb = parseList(rgbText, "rgb.txt");
    const std::vector<tum::Listed> depth = parseList(depthText, "depth.txt");
    checkPairing(rgb, depth);
    checkFrameRate(rgb);

    std::istringstream associations{std::string(input)};
    try {
        for (const tum::Association& a : tum::parseAssociations(associations, "associations.txt")) {
            checkListed({a.rgb});
            checkListed({a.depth});
            FUZZ_CHECK(a.rgb.line == a.depth.line, "halves of one line on lines %zu and %zu", a.rgb.line,
                       a.depth.line);
        }
    } catch (const SourceError& e) {
        checkMessage(e, "associations.txt", input);
    }
    return 0;
}
