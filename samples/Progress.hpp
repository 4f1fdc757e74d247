// A one-line progress bar for terminals: frame i/N, frames per second and time left.
#pragma once

#include <chrono>
#include <cstddef>
#include <optional>

namespace defocus {

class Progress {
public:
    /// Draws only when stderr is a terminal and `enabled`.
    Progress(std::optional<std::size_t> total, bool enabled);
    /// Call after each frame.
    void update(std::size_t done);
    /// Clears the bar so the summary line starts on a clean line.
    void finish();

private:
    std::optional<std::size_t> total_;
    bool active_;
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point lastDraw_;
};

} // namespace defocus
