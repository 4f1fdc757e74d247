// SPDX-License-Identifier: LGPL-2.1-or-later
// GPU time per pass from GL_TIME_ELAPSED queries, double-buffered: the results read after a
// frame are those of the frame before, which the GPU has long finished, so reading them never
// stalls the pipeline. With finishEachScope(true) (profiling), each scope instead waits for the
// GPU at its start and end (glFinish) and reports the wall time in between: on llvmpipe, which
// defers rendering to a flush, the queries' times need not fall where the passes were issued.
#pragma once

#include <chrono>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "filter/gl/Objects.hpp"

namespace defocus::gl {

class GpuTimer {
public:
    using Results = std::vector<std::pair<std::string, double>>; ///< (scope name, milliseconds)

    /// `enabled` false makes every call a no-op (drivers without timer queries).
    explicit GpuTimer(bool enabled = true);

    /// Starts timing the scope `name` (scopes do not nest).
    void begin(std::string_view name);
    void end();
    /// Profiling: glFinish around every scope, wall-clock times instead of queries. Slows the
    /// frame (no overlap of CPU and GPU work), so for per-pass figures only.
    void finishEachScope(bool on) { finish_ = on; }
    bool finishesEachScope() const { return finish_; }
    /// Ends the current frame's set of scopes and returns the previous frame's results
    /// (empty after the first frame).
    Results swap();
    /// Returns the results of the frame ended by the last swap(), waiting for the GPU: for the
    /// end of a stream.
    Results drain();

private:
    struct Scope {
        std::string name;
        Handle<deleteQuery> query;
        double wallMs = -1.0; ///< finishEachScope: measured on the CPU; -1: read the query
    };
    struct Set {
        std::vector<Scope> scopes; ///< pool, reused
        std::size_t used = 0;      ///< scopes begun in this set's frame
    };
    Results read(Set& set);

    bool enabled_;
    bool finish_ = false;
    std::chrono::steady_clock::time_point started_;
    Set sets_[2];
    int current_ = 0;
};

} // namespace defocus::gl
