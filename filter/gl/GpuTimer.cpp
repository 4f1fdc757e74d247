// SPDX-License-Identifier: LGPL-2.1-or-later
// GL_TIME_ELAPSED query pools, a set per frame.
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

std::size_t GpuTimer::open(std::uint64_t frame)
{
    for (std::size_t i = 0; i < sets_.size(); ++i)
        if (sets_[i].state == State::Open && sets_[i].frame == frame)
            return i;
    std::size_t i = 0;
    while (i < sets_.size() && sets_[i].state != State::Free)
        ++i;
    if (i == sets_.size())
        sets_.emplace_back();
    sets_[i].state = State::Open;
    sets_[i].frame = frame;
    sets_[i].used = 0;
    return i;
}

void GpuTimer::begin(std::string_view name, std::uint64_t frame)
{
    if (!enabled_ && !finish_)
        return;
    timing_ = open(frame);
    Set& set = sets_[timing_];
    if (set.used == set.scopes.size())
        set.scopes.push_back({std::string(name), Handle<deleteQuery>(0)});
    Scope& scope = set.scopes[set.used];
    scope.name = name;
    if (finish_) {
        glFinish();
        started_ = std::chrono::steady_clock::now();
        return;
    }
    if (!scope.query) { // new, or made by a finishEachScope frame
        GLuint id = 0;
        glCreateQueries(GL_TIME_ELAPSED, 1, &id);
        scope.query = Handle<deleteQuery>(id);
    }
    scope.wallMs = -1.0;
    glBeginQuery(GL_TIME_ELAPSED, scope.query.id());
}

void GpuTimer::end()
{
    if (finish_) {
        glFinish();
        sets_[timing_].scopes[sets_[timing_].used++].wallMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started_).count();
        return;
    }
    if (!enabled_)
        return;
    glEndQuery(GL_TIME_ELAPSED);
    ++sets_[timing_].used;
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
    release(set);
    return results;
}

GpuTimer::Results GpuTimer::swap(std::uint64_t frame)
{
    if (!enabled_ && !finish_)
        return {};
    const std::size_t ending = open(frame);
    for (Set& set : sets_)
        if (set.state == State::Open && set.frame < frame)
            release(set);
    Results results;
    if (ended_ != kNoSet)
        results = read(sets_[ended_]);
    sets_[ending].state = State::Ended;
    ended_ = ending;
    return results;
}

GpuTimer::Results GpuTimer::drain()
{
    if (ended_ == kNoSet)
        return {};
    const std::size_t set = std::exchange(ended_, kNoSet);
    return read(sets_[set]);
}

void GpuTimer::forget(std::uint64_t frame)
{
    for (Set& set : sets_)
        if (set.state == State::Open && set.frame == frame)
            release(set);
}

} // namespace defocus::gl
