// GL_TIME_ELAPSED query pool.
#include "filter/gl/GpuTimer.hpp"

namespace defocus::gl {

void GpuTimer::begin(const std::string& name)
{
    if (!enabled_)
        return;
    if (used_ == scopes_.size()) {
        GLuint id = 0;
        glCreateQueries(GL_TIME_ELAPSED, 1, &id);
        scopes_.push_back({name, Handle<deleteQuery>(id)});
    }
    scopes_[used_].name = name;
    glBeginQuery(GL_TIME_ELAPSED, scopes_[used_].query.id());
}

void GpuTimer::end()
{
    if (!enabled_)
        return;
    glEndQuery(GL_TIME_ELAPSED);
    ++used_;
}

std::vector<std::pair<std::string, double>> GpuTimer::collect()
{
    std::vector<std::pair<std::string, double>> results;
    for (std::size_t i = 0; i < used_; ++i) {
        GLuint64 ns = 0;
        glGetQueryObjectui64v(scopes_[i].query.id(), GL_QUERY_RESULT, &ns);
        results.emplace_back(scopes_[i].name, static_cast<double>(ns) * 1e-6);
    }
    used_ = 0;
    return results;
}

} // namespace defocus::gl
