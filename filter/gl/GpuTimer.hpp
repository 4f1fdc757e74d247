// SPDX-License-Identifier: LGPL-2.1-or-later
// GPU time per pass from GL_TIME_ELAPSED queries, a set of scopes per frame and read one frame
// late: the results read when a frame ends are those of the frame ended before it, which the GPU
// has long finished, so reading them never stalls the pipeline. Each scope names the frame it
// belongs to, so a frame begun ahead (its depth prep timed before the passes of the frame before
// it) keeps its scopes apart from that frame's. With finishEachScope(true) (profiling), each scope
// instead waits for the GPU at its start and end (glFinish) and reports the wall time in between:
// on llvmpipe, which defers rendering to a flush, the queries' times need not fall where the
// passes were issued.
#pragma once

#include <chrono>
#include <cstdint>
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

    /// Starts timing the scope `name` of frame `frame` (the caller's number for it; scopes do not
    /// nest). A frame's scopes go to the set it has open, or to a new one after swap(frame).
    void begin(std::string_view name, std::uint64_t frame = 0);
    void end();
    /// Profiling: glFinish around every scope, wall-clock times instead of queries. Slows the
    /// frame (no overlap of CPU and GPU work), so for per-pass figures only.
    void finishEachScope(bool on) { finish_ = on; }
    bool finishesEachScope() const { return finish_; }
    /// Ends frame `frame`'s open set of scopes and returns the results of the set ended before
    /// it (empty the first time). The open sets of frames numbered below `frame`, never ended
    /// (a frame processed and not read), are dropped.
    Results swap(std::uint64_t frame = 0);
    /// Returns the results of the set ended by the last swap(), waiting for the GPU: for the end
    /// of a stream.
    Results drain();
    /// Drops frame `frame`'s open set (a frame begun and never finished).
    void forget(std::uint64_t frame);

private:
    struct Scope {
        std::string name;
        Handle<deleteQuery> query;
        double wallMs = -1.0; ///< finishEachScope: measured on the CPU; -1: read the query
    };
    enum class State { Free, Open, Ended };
    struct Set {
        State state = State::Free;
        std::uint64_t frame = 0;
        std::vector<Scope> scopes; ///< pool, reused
        std::size_t used = 0;      ///< scopes begun in this set's frame
    };
    /// The index of frame `frame`'s open set, opened from a free one (or a new one) if need be.
    std::size_t open(std::uint64_t frame);
    /// Frees `set` for another frame (its queries are kept, to be reused).
    static void release(Set& set)
    {
        set.used = 0;
        set.state = State::Free;
    }
    static constexpr std::size_t kNoSet = static_cast<std::size_t>(-1);
    Results read(Set& set);

    bool enabled_;
    bool finish_ = false;
    std::chrono::steady_clock::time_point started_;
    std::vector<Set> sets_;
    std::size_t timing_ = 0;                     ///< the set of the scope begun
    std::size_t ended_ = kNoSet;                 ///< the set ended by the last swap()
};

} // namespace defocus::gl
