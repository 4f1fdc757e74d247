// SPDX-License-Identifier: LGPL-2.1-or-later
// Progress on stderr: a bar redrawn at most ten times a second on a terminal, a log line every
// interval elsewhere.
#include "samples/Progress.hpp"

#include <algorithm>
#include <cstdio>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

namespace defocus {

Progress::Progress(std::optional<std::size_t> total, bool enabled, std::chrono::duration<double> interval)
    : total_(total), active_(enabled), terminal_(isatty(fileno(stderr)) != 0), interval_(interval),
      start_(std::chrono::steady_clock::now()), lastDraw_(start_)
{
}

std::string Progress::line(std::size_t done, std::optional<std::size_t> total, double seconds)
{
    const double fps = seconds > 0.0 ? static_cast<double>(done) / seconds : 0.0;
    if (!total || *total == 0)
        return fmt::format("{} frames, {:.1f} fps", done, fps);
    const auto left = static_cast<int>(fps > 0.0 && *total > done ? static_cast<double>(*total - done) / fps : 0.0);
    return fmt::format("{}/{} frames, {:.1f} fps, {}:{:02} left", done, *total, fps, left / 60, left % 60);
}

void Progress::update(std::size_t done)
{
    if (!active_)
        return;
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - start_).count();
    if (!terminal_) {
        // A log keeps every line: one per interval, none redrawn.
        if (now - lastDraw_ < interval_)
            return;
        lastDraw_ = now;
        spdlog::info("{}", line(done, total_, seconds));
        return;
    }
    const bool last = total_ && done >= *total_;
    if (!last && now - lastDraw_ < std::chrono::milliseconds(100))
        return;
    lastDraw_ = now;
    std::string bar;
    if (total_ && *total_ > 0) {
        constexpr int width = 30;
        const auto filled = static_cast<int>(width * static_cast<double>(std::min(done, *total_)) /
                                             static_cast<double>(*total_));
        bar = fmt::format("[{}{}] ", std::string(static_cast<std::size_t>(filled), '#'),
                          std::string(static_cast<std::size_t>(width - filled), '.'));
    }
    std::fprintf(stderr, "\r%s%s\033[K", bar.c_str(), line(done, total_, seconds).c_str());
    std::fflush(stderr);
}

void Progress::finish()
{
    if (active_ && terminal_)
        std::fprintf(stderr, "\r\033[K");
}

} // namespace defocus
