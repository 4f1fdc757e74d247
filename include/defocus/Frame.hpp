// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus::Frame: one RGB-D frame as a source gives it and the filter takes it: colour, depth in
// metres, when it was captured and where it came from (for messages). defocus::Source gives
// them; the command line's sources and sinks pass them along.
#pragma once

#include <cstddef>
#include <string>

#include <opencv2/core.hpp>

namespace defocus {

struct Frame {
    /// Colour, BGR channel order: CV_8UC3 sRGB-encoded, or CV_32FC3 scene-linear (EXR and other
    /// float inputs; values well above 1 are kept).
    cv::Mat color;
    /// Depth along the view axis, metres, CV_32FC1, its own size (Filter::process resizes it to
    /// the colour by nearest neighbour). 0, negative, NaN and infinities mean "no measurement".
    /// Empty: no depth at all; the frame passes through in focus.
    cv::Mat depth;
    /// Capture time, seconds, on the source's clock (file names, TUM lists, a camera's
    /// CLOCK_MONOTONIC); 0 where unknown.
    double timestampS = 0.0;
    /// Frames since the start, from 0.
    std::size_t index = 0;
    /// Where it came from, for messages, e.g. "rgb/1305031102.175304.png".
    std::string name;
};

} // namespace defocus
