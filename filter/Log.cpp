// SPDX-License-Identifier: LGPL-2.1-or-later
// The library's logger: one sink that hands each message to the handler, or writes it to
// standard error when there is none (filter/Log.hpp).
#include "filter/Log.hpp"

#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include <spdlog/sinks/base_sink.h>

namespace defocus {
namespace {

spdlog::level::level_enum spdlogLevel(LogLevel level)
{
    switch (level) {
    case LogLevel::Debug: return spdlog::level::debug;
    case LogLevel::Info: return spdlog::level::info;
    case LogLevel::Warning: return spdlog::level::warn;
    case LogLevel::Error: break;
    }
    return spdlog::level::err;
}

LogLevel levelOf(spdlog::level::level_enum level)
{
    switch (level) {
    case spdlog::level::trace:
    case spdlog::level::debug: return LogLevel::Debug;
    case spdlog::level::info: return LogLevel::Info;
    case spdlog::level::warn: return LogLevel::Warning;
    default: return LogLevel::Error;
    }
}

/// base_sink serialises the calls (its mutex), so the handler is swapped under the same lock.
class HandlerSink final : public spdlog::sinks::base_sink<std::mutex> {
public:
    void setHandler(LogHandler handler)
    {
        std::lock_guard lock(mutex_);
        handler_ = std::move(handler);
    }

protected:
    void sink_it_(const spdlog::details::log_msg& message) override
    {
        const std::string_view text(message.payload.data(), message.payload.size());
        if (handler_) {
            handler_(levelOf(message.level), text);
            return;
        }
        const auto name = spdlog::level::to_string_view(message.level);
        std::fprintf(stderr, "defocus: %.*s: %.*s\n", static_cast<int>(name.size()), name.data(),
                     static_cast<int>(text.size()), text.data());
    }
    void flush_() override { std::fflush(stderr); }

private:
    LogHandler handler_;
};

struct Logger {
    std::shared_ptr<HandlerSink> sink = std::make_shared<HandlerSink>();
    spdlog::logger logger{"defocus", sink};
    Logger() { logger.set_level(spdlog::level::info); }
};

Logger& instance()
{
    static Logger the;
    return the;
}

} // namespace

spdlog::logger& logger()
{
    return instance().logger;
}

namespace detail {
void setLogHandler(LogHandler handler, LogLevel least)
{
    Logger& l = instance();
    const bool custom = static_cast<bool>(handler);
    l.sink->setHandler(std::move(handler));
    l.logger.set_level(custom ? spdlogLevel(least) : spdlog::level::info);
}
} // namespace detail

} // namespace defocus
