// Progress bar on stderr, redrawn at most ten times a second.
#include "samples/Progress.hpp"

#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <unistd.h>

namespace defocus {

Progress::Progress(std::optional<std::size_t> total, bool enabled)
    : total_(total), active_(enabled && isatty(fileno(stderr)) != 0), start_(std::chrono::steady_clock::now()),
      lastDraw_(start_)
{
}

void Progress::update(std::size_t done)
{
    if (!active_)
        return;
    const auto now = std::chrono::steady_clock::now();
    const bool last = total_ && done >= *total_;
    if (!last && now - lastDraw_ < std::chrono::milliseconds(100))
        return;
    lastDraw_ = now;
    const double seconds = std::chrono::duration<double>(now - start_).count();
    const double fps = seconds > 0.0 ? static_cast<double>(done) / seconds : 0.0;
    std::string line;
    if (total_ && *total_ > 0) {
        constexpr int width = 30;
        const auto filled = static_cast<int>(width * static_cast<double>(done) / static_cast<double>(*total_));
        const double eta = fps > 0.0 ? static_cast<double>(*total_ - done) / fps : 0.0;
        line = fmt::format("[{}{}] {}/{}  {:.1f} fps  ETA {}:{:02}", std::string(static_cast<std::size_t>(filled), '#'),
                           std::string(static_cast<std::size_t>(width - filled), '.'), done, *total_, fps,
                           static_cast<int>(eta) / 60, static_cast<int>(eta) % 60);
    } else {
        line = fmt::format("frame {}  {:.1f} fps", done, fps);
    }
    std::fprintf(stderr, "\r%s\033[K", line.c_str());
    std::fflush(stderr);
}

void Progress::finish()
{
    if (active_)
        std::fprintf(stderr, "\r\033[K");
}

} // namespace defocus
