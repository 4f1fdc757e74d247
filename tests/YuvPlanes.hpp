// SPDX-License-Identifier: LGPL-2.1-or-later
// Y'CbCr test frames made by OpenCV, as planes (defocus::YuvImage) and packed one plane after the
// other as GStreamer's I420, NV12 and YUY2 buffers and OpenCV's cvtColor hold them (the tests of
// the public API and of the GStreamer element include it beside the installed headers, and
// defocus-bench throughput --versus-yuv makes its frames with it).
#pragma once

#include <vector>

#include <defocus/Frame.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace defocus::test {

/// `bgr` (even width and height) as Y'CbCr 4:2:0 planes by OpenCV (BT.601, limited range):
/// I420, or NV12, or YUYV with each 2x2 block's chroma on both of its rows; each plane owns its
/// pixels.
inline YuvImage opencvYuv(const cv::Mat& bgr, YuvImage::Layout layout)
{
    cv::Mat i420;
    cv::cvtColor(bgr, i420, cv::COLOR_BGR2YUV_I420); // Y rows, then Cb, then Cr, each packed
    const int w = bgr.cols, h = bgr.rows;
    YuvImage yuv;
    yuv.layout = layout;
    yuv.matrix = YuvImage::Matrix::Bt601;
    yuv.range = YuvImage::Range::Limited;
    yuv.y = i420.rowRange(0, h).clone();
    const cv::Mat cb = cv::Mat(h / 2, w / 2, CV_8UC1, i420.ptr(h)).clone();
    const cv::Mat cr = cv::Mat(h / 2, w / 2, CV_8UC1, i420.ptr(h) + (w / 2) * (h / 2)).clone();
    if (layout == YuvImage::Layout::Nv12) {
        cv::merge(std::vector<cv::Mat>{cb, cr}, yuv.u);
    } else if (layout == YuvImage::Layout::Yuyv) {
        cv::Mat pairs(h, w, CV_8UC2);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                pairs.at<cv::Vec2b>(y, x) = {yuv.y.at<uchar>(y, x), (x % 2 == 0 ? cb : cr).at<uchar>(y / 2, x / 2)};
        yuv.y = pairs;
    } else {
        yuv.u = cb;
        yuv.v = cr;
    }
    return yuv;
}

/// `yuv`'s planes one after the other, rows tightly packed, as one CV_8UC1 image of 3/2 its
/// height: Y, then Cb and Cr (I420) or Cb and Cr interleaved (NV12); YUYV's one plane as it is
/// (CV_8UC2).
inline cv::Mat packedPlanes(const YuvImage& yuv)
{
    if (yuv.layout == YuvImage::Layout::Yuyv)
        return yuv.y.clone();
    const int w = yuv.y.cols, h = yuv.y.rows;
    cv::Mat packed(h * 3 / 2, w, CV_8UC1);
    yuv.y.copyTo(packed.rowRange(0, h));
    uchar* chroma = packed.ptr(h);
    for (const cv::Mat* plane : {&yuv.u, &yuv.v}) {
        if (plane->empty())
            continue;
        plane->copyTo(cv::Mat(plane->size(), plane->type(), chroma));
        chroma += plane->total() * plane->elemSize();
    }
    return packed;
}

/// The layout's name, as GStreamer and V4L2 spell it.
inline const char* layoutName(YuvImage::Layout layout)
{
    return layout == YuvImage::Layout::I420 ? "I420" : layout == YuvImage::Layout::Nv12 ? "NV12" : "YUYV";
}

/// The cvtColor code from packedPlanes() of `layout` to BGR.
inline int opencvToBgr(YuvImage::Layout layout)
{
    return layout == YuvImage::Layout::I420   ? cv::COLOR_YUV2BGR_I420
           : layout == YuvImage::Layout::Nv12 ? cv::COLOR_YUV2BGR_NV12
                                              : cv::COLOR_YUV2BGR_YUY2;
}

} // namespace defocus::test
