// SPDX-License-Identifier: LGPL-2.1-or-later
// One RGB-D frame as it travels from a source to the filter: colour, depth in metres, and where
// it came from (for messages). Sources fill it; the pipeline reads it.
#pragma once

#include <cstddef>
#include <string>

#include <opencv2/core.hpp>

namespace defocus {

struct Frame {
    /// Colour, BGR channel order. Either CV_8UC3 (sRGB-encoded, decoded to linear light on the
    /// GPU) or CV_32FC3 (scene-linear, may be HDR: values well above 1 are kept).
    cv::Mat color;
    /// Depth along the view axis in metres, CV_32FC1, any size (resized to the colour size with
    /// nearest-neighbour sampling). 0, negative, NaN and +-Inf mean "no measurement".
    /// Empty means no depth at all: the frame passes through in focus.
    cv::Mat depth;
    /// Capture time in seconds (source clock); 0 when unknown.
    double timestamp = 0.0;
    /// Position in the clip, from 0.
    std::size_t index = 0;
    /// Human-readable origin for messages, e.g. "rgb/1305031250.261917.png".
    std::string name;
};

} // namespace defocus
