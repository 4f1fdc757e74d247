// SPDX-License-Identifier: LGPL-2.1-or-later
// libdefocus' messages inside GStreamer: to the debug category "defocuslib" (GST_DEBUG=defocuslib:5),
// never to standard output (which may carry the video: `gst-launch-1.0 -q ... ! fdsink`), and its
// warnings as warning messages of the element that made the call, which a user sees.
#pragma once

#include <gst/gst.h>

namespace defocus::gst {

/// Takes the library's messages (defocus::setLogHandler); once, when the plugin loads.
void takeLibraryLog();

/// While one lives, the library's messages on this thread are `element`'s.
class LibraryCall {
public:
    explicit LibraryCall(GstElement* element);
    ~LibraryCall();
    LibraryCall(const LibraryCall&) = delete;
    LibraryCall& operator=(const LibraryCall&) = delete;

private:
    GstElement* previous_;
};

} // namespace defocus::gst
