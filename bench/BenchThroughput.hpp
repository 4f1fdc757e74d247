// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus-bench throughput: frames per second of a clip through the public Filter one frame at a
// time (process()) against frames in flight (submit()/receive()), in one run, interleaved, and
// the calling thread's CPU time per frame in each (its own work: what it spends not waiting).
//   defocus-bench throughput                                     (640x480 and 1920x1080, balanced)
//   defocus-bench throughput --sizes 3840x2160 --frames 60 --passes 5 --quality high
//   defocus-bench throughput --versus-i420                       (colour as I420 planes against BGR)
//   defocus-bench throughput --versus-yuv yuyv                   (a webcam's YUYV, or nv12, against BGR)
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace defocus {

struct ThroughputOptions {
    std::string data = "data/tum_fr1_rpy";                  ///< TUM folder, its frames resized
    std::vector<cv::Size> sizes{{640, 480}, {1920, 1080}};  ///< frame sizes timed
    std::string preset = "balanced";                        ///< quality preset
    int frames = 30;                                        ///< frames per timed pass
    int passes = 3;                                         ///< passes per mode, interleaved
    /// Instead: frames in flight with the colour as Y'CbCr planes of this layout ("i420", "nv12"
    /// or "yuyv"; OpenCV's BT.601 limited range) against the same frames as BGR (yuvToBgr() of
    /// them), interleaved, and that both give the same bytes. Empty: one at a time against in
    /// flight.
    std::string versusYuv;
};

/// Prints a table per size and checks that both ways give the same bytes; returns the exit
/// status (0; 1 where the outputs differ or the clip cannot be read).
int runThroughput(const ThroughputOptions& options);

} // namespace defocus
