// SPDX-License-Identifier: LGPL-2.1-or-later
// The public logging hook (include/defocus/Log.hpp) over the library's logger (filter/Log.hpp).
#include "defocus/Log.hpp"

#include <utility>

#include "filter/Log.hpp"

namespace defocus {

void setLogHandler(LogHandler handler, LogLevel least)
{
    detail::setLogHandler(std::move(handler), least);
}

} // namespace defocus
