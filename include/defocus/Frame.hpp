// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus::Frame: one RGB-D frame as a source gives it and the filter takes it: colour, depth (in
// metres, or in the units a 16-bit file or camera stored), when it was captured and where it
// came from (for messages). defocus::Source gives them; the command line's sources and sinks pass
// them along. defocus::YuvImage: colour as a video decoder or camera gives it, which the filter
// also takes and a frame may hold instead of BGR.
#pragma once

#include <cstddef>
#include <string>

#include <opencv2/core.hpp>

#include "defocus/Export.hpp"

namespace defocus {

/// A colour image as video decoders and cameras give it: 8-bit Y'CbCr 4:2:0, planar (I420: Y, then
/// Cb, then Cr) or semi-planar (NV12: Y, then Cb and Cr interleaved), or 4:2:2 packed as webcams
/// send it (YUYV, GStreamer's YUY2: Y0 Cb Y1 Cr for each pair of pixels), each plane a cv::Mat
/// that may view the caller's buffer (a GstVideoFrame's planes, a V4L2 buffer; rows may have
/// padding).
/// Filter::process() and submit() take it as they take BGR: on a GPU its planes go up as they are,
/// half the bytes of BGR, and become colour there; where the CPU prepares depth (a software
/// renderer) they become BGR on the CPU. Either way the filter sees yuvToBgr() of it.
struct YuvImage {
    enum class Layout {
        I420, ///< u: Cb (CV_8UC1), v: Cr (CV_8UC1)
        Nv12, ///< u: Cb and Cr interleaved (CV_8UC2), v: empty
        /// y: the packed pairs (CV_8UC2, the image's size, an even width): Y' in the first
        /// channel, Cb (even columns) or Cr (odd columns) of the pair in the second; u, v: empty
        Yuyv
    };
    /// The matrix from R'G'B' to Y'CbCr: BT.601 (standard-definition video, JPEG) or BT.709 (HD).
    enum class Matrix { Bt601, Bt709 };
    /// Limited ("TV", "studio"): Y' in 16..235, Cb and Cr in 16..240; full ("PC", JPEG): 0..255.
    enum class Range { Limited, Full };

    Layout layout = Layout::I420;
    Matrix matrix = Matrix::Bt709;
    Range range = Range::Limited;
    cv::Mat y; ///< CV_8UC1 luma, the image's size (YUYV: see Layout)
    cv::Mat u; ///< chroma at half the width and height, rounded up (see Layout)
    cv::Mat v;
};

struct Frame {
    /// Colour, BGR channel order: CV_8UC3 sRGB-encoded, or CV_32FC3 scene-linear (EXR and other
    /// float inputs; values well above 1 are kept). Empty where `yuv` holds the colour.
    cv::Mat color;
    /// Depth along the view axis, its own size (Filter::process resizes it to the colour by nearest
    /// neighbour): CV_32FC1 metres, where 0, negative, NaN and infinities mean "no measurement";
    /// or, from a Source with SourceSettings::depthUnits, CV_16UC1 as a 16-bit depth file or camera
    /// stored it, `depthScale` units per metre, 0 = no measurement (what Filter::process uploads
    /// as it is with Settings::depthScale the same). depthMetres() gives metres either way.
    /// Empty: no depth at all; the frame passes through in focus.
    cv::Mat depth;
    /// Capture time, seconds, on the source's clock (file names, TUM lists, a camera's
    /// CLOCK_MONOTONIC); 0 where unknown.
    double timestampS = 0.0;
    /// Frames since the start, from 0.
    std::size_t index = 0;
    /// Where it came from, for messages, e.g. "rgb/1305031102.175304.png".
    std::string name;
    /// Units per metre of CV_16UC1 `depth` (> 0); 0 where `depth` is metres or empty.
    double depthScale = 0.0;
    /// Colour as a camera captured it, from a Source with SourceSettings::yuvColor where the
    /// camera sends Y'CbCr (YUYV, NV12): its planes, owned by the frame, for Filter::process to
    /// upload as they are (Filter::process(const Frame&) takes either); `color` is then empty.
    /// Otherwise its planes are empty. colorBgr() gives BGR either way.
    YuvImage yuv = {};
};

/// `frame.depth` as CV_32FC1 metres: 16-bit depth divided by its depthScale (0 stays 0), metres
/// as they are (the same pixels, not a copy), empty as it is.
inline cv::Mat depthMetres(const Frame& frame)
{
    if (frame.depth.type() != CV_16UC1 || frame.depth.empty())
        return frame.depth;
    CV_Assert(frame.depthScale > 0.0);
    cv::Mat metres;
    frame.depth.convertTo(metres, CV_32F, 1.0 / frame.depthScale);
    return metres;
}

/// `frame.color`, or where that is empty and `frame.yuv` holds the colour, yuvToBgr() of it
/// (include/defocus/Filter.hpp): CV_8UC3 BGR.
DEFOCUS_API cv::Mat colorBgr(const Frame& frame);

/// The size of the frame's colour, `color` or `yuv`; 0x0 where it has none.
inline cv::Size colorSize(const Frame& frame)
{
    return frame.color.empty() ? frame.yuv.y.size() : frame.color.size();
}

} // namespace defocus
