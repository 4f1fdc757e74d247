// SPDX-License-Identifier: LGPL-2.1-or-later
// Double-buffered GL_TIME_ELAPSED query pools.
#include "filter/gl/GpuTimer.hpp"

namespace defocus::gl {

namespace {

constexpr GLuint64 kLongestScopeNs = 60'000'000'000; // a minute

} // namespace

GpuTimer::GpuTimer(bool enabled) : enabled_(enabled)
{
    if (!enabled_)
        return;
    // Some drivers (llvmpipe) report garbage for the very first query of a context: spend it here.
    GLuint id = 0;
    glCreateQueries(GL_TIME_ELAPSED, 1, &id);
    glBeginQuery(GL_TIME_ELAPSED, id);
    glEndQuery(GL_TIME_ELAPSED);
    GLuint64 unused = 0;
    glGetQueryObjectui64v(id, GL_QUERY_RESULT, &unused);
    glDeleteQueries(1, &id);
}

void GpuTimer::begin(std::string_view name)
{
    if (finish_) {
        glFinish();
        Set& set = sets_[current_];
        if (set.used == set.scopes.size())
            set.scopes.push_back({std::string(name), Handle<deleteQuery>(0)});
        set.scopes[set.used].name = name;
        started_ = std::chrono::steady_clock::now();
        return;
    }
    if (!enabled_)
        return;
    Set& set = sets_[current_];
    if (set.used == set.scopes.size()) {
        GLuint id = 0;
        glCreateQueries(GL_TIME_ELAPSED, 1, &id);
        set.scopes.push_back({std::string(name), Handle<deleteQuery>(id)});
    }
    if (!set.scopes[set.used].query) { // made by a finishEachScope frame
        GLuint id = 0;
        glCreateQueries(GL_TIME_ELAPSED, 1, &id);
        set.scopes[set.used].query = Handle<deleteQuery>(id);
    }
    set.scopes[set.used].name = name;
    set.scopes[set.used].wallMs = -1.0;
    glBeginQuery(GL_TIME_ELAPSED, set.scopes[set.used].query.id());
}

void GpuTimer::end()
{
    if (finish_) {
        glFinish();
        sets_[current_].scopes[sets_[current_].used++].wallMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started_).count();
        return;
    }
    if (!enabled_)
        return;
    glEndQuery(GL_TIME_ELAPSED);
    ++sets_[current_].used;
}

GpuTimer::Results GpuTimer::read(Set& set)
{
    Results results;
    for (std::size_t i = 0; i < set.used; ++i) {
        GLuint64 ns = 0;
        if (set.scopes[i].wallMs >= 0.0)
            ns = static_cast<GLuint64>(set.scopes[i].wallMs * 1e6);
        else if (set.scopes[i].query)
            glGetQueryObjectui64v(set.scopes[i].query.id(), GL_QUERY_RESULT, &ns);
        else
            continue;
        // llvmpipe sometimes reports the time since boot for a scope (seen on the first scope of
        // every frame of `defocus --demo`, where the synthetic renderer's draws come between
        // frames; the cause is not found): a scope that long did not run that long, so it is
        // reported as missing rather than as hours.
        if (ns > kLongestScopeNs)
            continue;
        // Passes timed in several scopes (blur tiles + copy tiles) add up under one name.
        if (!results.empty() && results.back().first == set.scopes[i].name)
            results.back().second += static_cast<double>(ns) * 1e-6;
        else
            results.emplace_back(set.scopes[i].name, static_cast<double>(ns) * 1e-6);
    }
    set.used = 0;
    return results;
}

GpuTimer::Results GpuTimer::swap()
{
    current_ = 1 - current_;
    return read(sets_[current_]);
}

GpuTimer::Results GpuTimer::drain()
{
    // After swap() the frame just ended is in the other set.
    return read(sets_[1 - current_]);
}

} // namespace defocus::gl
