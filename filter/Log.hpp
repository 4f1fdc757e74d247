// SPDX-License-Identifier: LGPL-2.1-or-later
// The logger the library's code writes its messages through: `logger().warn("...", ...)`. Where
// they go is set by setLogHandler (include/defocus/Log.hpp); never standard output. Internal.
#pragma once

#include <spdlog/logger.h>

#include "defocus/Log.hpp"

namespace defocus {

/// The library's logger (not spdlog's default logger, which belongs to the program).
spdlog::logger& logger();

namespace detail {
/// setLogHandler of this copy of the library's code (the shared library and a program linking
/// the static parts each have one).
void setLogHandler(LogHandler handler, LogLevel least);
} // namespace detail

} // namespace defocus
