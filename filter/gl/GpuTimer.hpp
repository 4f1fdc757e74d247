// GPU time per pass from GL_TIME_ELAPSED queries. One query object per named scope, reused
// every frame; results are collected after the frame's readback, when the GPU is done anyway.
#pragma once

#include <string>
#include <vector>

#include "filter/gl/Objects.hpp"

namespace defocus::gl {

class GpuTimer {
public:
    /// `enabled` false makes every call a no-op (drivers without timer queries).
    explicit GpuTimer(bool enabled = true) : enabled_(enabled) {}

    /// Starts timing the scope `name` (scopes do not nest).
    void begin(const std::string& name);
    void end();
    /// Collects the results of the scopes timed since the last call: (name, milliseconds).
    /// Waits for the GPU if it has not finished.
    std::vector<std::pair<std::string, double>> collect();

private:
    struct Scope {
        std::string name;
        Handle<deleteQuery> query;
    };
    bool enabled_;
    std::vector<Scope> scopes_;   ///< pool, reused frame after frame
    std::size_t used_ = 0;        ///< scopes begun since the last collect()
};

} // namespace defocus::gl
