// SPDX-License-Identifier: LGPL-2.1-or-later
// libdefocus' messages to a GStreamer debug category and element warnings (gst/LibraryLog.hpp).
#include "gst/LibraryLog.hpp"

#include <string>

#include <defocus/Log.hpp>

GST_DEBUG_CATEGORY_STATIC(defocus_library_debug);

namespace defocus::gst {
namespace {

thread_local GstElement* current = nullptr; ///< the element calling the library on this thread

GstDebugLevel gstLevel(LogLevel level)
{
    switch (level) {
    case LogLevel::Debug: return GST_LEVEL_DEBUG;
    case LogLevel::Info: return GST_LEVEL_INFO;
    case LogLevel::Warning: return GST_LEVEL_WARNING;
    case LogLevel::Error: break;
    }
    return GST_LEVEL_ERROR;
}

void log(LogLevel level, std::string_view message)
{
    const std::string text(message);
    GST_CAT_LEVEL_LOG(defocus_library_debug, gstLevel(level), current, "%s", text.c_str());
    // Errors reach the element as exceptions, which it posts as error messages itself.
    if (level == LogLevel::Warning && current)
        GST_ELEMENT_WARNING(current, LIBRARY, FAILED, ("%s", text.c_str()), (nullptr));
}

} // namespace

void takeLibraryLog()
{
    GST_DEBUG_CATEGORY_INIT(defocus_library_debug, "defocuslib", 0, "libdefocus' messages");
    setLogHandler(log, LogLevel::Debug);
}

LibraryCall::LibraryCall(GstElement* element) : previous_(current)
{
    current = element;
}

LibraryCall::~LibraryCall()
{
    current = previous_;
}

} // namespace defocus::gst
