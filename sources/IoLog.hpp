// SPDX-License-Identifier: LGPL-2.1-or-later
// Where the sources' and sinks' messages go in a program. They log as libdefocus does (a depth
// folder shorter than the colour, a camera's format, a codec that does not open), through the
// copy of its logger that a program links with them; by default to standard error.
//   setIoLogHandler(cli::forwardLibraryLog, LogLevel::Debug);   // as the program's own lines
#pragma once

#include "defocus/Log.hpp"

namespace defocus {

/// defocus::setLogHandler for the sources and sinks linked into this program.
void setIoLogHandler(LogHandler handler, LogLevel least = LogLevel::Info);

} // namespace defocus
