// SPDX-License-Identifier: LGPL-2.1-or-later
// Progress on standard error: on a terminal a one-line bar (frame i/N, frames per second, time
// left) redrawn in place; elsewhere (a log file, Slurm, nohup, CI) a log line every few seconds
// with the same figures, as ffmpeg and rsync do.
#pragma once

#include <chrono>
#include <cstddef>
#include <optional>
#include <string>

namespace defocus {

class Progress {
public:
    /// Shows progress only when `enabled`: a bar when standard error is a terminal, else an info
    /// line every `interval` (0: after every frame).
    Progress(std::optional<std::size_t> total, bool enabled,
             std::chrono::duration<double> interval = std::chrono::seconds(5));
    /// Call after each frame.
    void update(std::size_t done);
    /// Clears the bar so the summary line starts on a clean line.
    void finish();
    /// "120/300 frames, 24.1 fps, 0:07 left" after `seconds`; "120 frames, 24.1 fps" without a total.
    static std::string line(std::size_t done, std::optional<std::size_t> total, double seconds);

private:
    std::optional<std::size_t> total_;
    bool active_;
    bool terminal_;
    std::chrono::duration<double> interval_;
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point lastDraw_;
};

} // namespace defocus
