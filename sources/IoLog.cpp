// SPDX-License-Identifier: LGPL-2.1-or-later
#include "sources/IoLog.hpp"

#include <utility>

#include "filter/Log.hpp"

namespace defocus {

void setIoLogHandler(LogHandler handler, LogLevel least)
{
    detail::setLogHandler(std::move(handler), least);
}

} // namespace defocus
