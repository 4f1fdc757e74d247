// SPDX-License-Identifier: LGPL-2.1-or-later
// Where libdefocus' messages go (a depth folder shorter than the colour, a codec that is missing,
// a camera that gives another size than asked, ...): by default one line each on standard error,
// "defocus: warning: ...", never on standard output, which stays the program's. A program or a
// plugin may take them instead:
//   defocus::setLogHandler([](defocus::LogLevel level, std::string_view message) { ... });
#pragma once

#include <functional>
#include <string_view>

#include "defocus/Export.hpp"

namespace defocus {

enum class LogLevel {
    Debug,   ///< what a developer follows (EGL platform tried, a codec that does not open)
    Info,    ///< what happens (a camera's format, a window closed)
    Warning, ///< what a user should know: the output is not what was asked for
    Error    ///< something failed; the call that failed also throws or returns an error
};

/// Called once per message, with its text (no level, no newline). Calls never overlap: they are
/// made one at a time, from whichever thread logs (a reader thread, the streaming thread).
using LogHandler = std::function<void(LogLevel level, std::string_view message)>;

/// Sends the library's messages of `least` and above to `handler` from now on; an empty handler
/// restores the default (standard error, "defocus: LEVEL: MESSAGE", Info and above).
DEFOCUS_API void setLogHandler(LogHandler handler, LogLevel least = LogLevel::Info);

} // namespace defocus
