// SPDX-License-Identifier: LGPL-2.1-or-later
// The one contract every input implements: a pull-based stream of RGB-D frames.
//   defocus data/tum_fr1_rpy -o out.mp4            (TUM layout: rgb.txt + depth.txt)
//   defocus rgb_dir/ --depth depth_dir/ -o out/    (pair of folders, matched by sorted name)
//   defocus photo.png --depth depth.png -o out.png (one colour file + one depth file)
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "defocus/Frame.hpp"

namespace defocus {

/// Thrown for anything wrong with the input on disk; the message names the file (and line or
/// frame) and what is wrong with it. What each kind of bad input gives:
///   missing input, depth or listed file ... SourceError at open ("LIST:LINE: listed file ... does
///                                            not exist" for TUM lists)
///   corrupt or truncated image ............. SourceError naming the file, from the first read of
///                                            it; unknown formats and sizes over kMaxImagePixels
///                                            are refused before decoding (ImageIO.hpp)
///   truncated or damaged video ............. a file that does not open: SourceError at open; one
///                                            that stops early: a warning with both frame counts,
///                                            and the frames decoded so far go through
///   depth of another size than colour ...... scaled to the colour size by the pipeline; another
///                                            aspect ratio: SourceError naming both files and sizes
///   unequal colour and depth counts ........ folder pair: SourceError at open naming both folders
///                                            and counts; TUM: colour frames with no depth within
///                                            20 ms pass through in focus, with one warning
///   wrong bit depth or channel count ....... SourceError naming the file and its sample format
///   empty folder or list ................... SourceError at open naming it
///   garbage line in a TUM list ............. SourceError "LIST:LINE: expected '...', got '...'"
class SourceError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A device that exists but is in use by another program (a camera another process captures
/// from): trying again later may work, so the programs exit with 75 (ExitStatus.hpp), not 1.
class DeviceBusy : public SourceError {
public:
    using SourceError::SourceError;
};

class FrameSource {
public:
    virtual ~FrameSource() = default;
    /// The next frame, or nullopt at the end of the stream. Throws SourceError when a frame
    /// cannot be read; the stream may not be resumed after that.
    virtual std::optional<Frame> next() = 0;
    /// The reading of one frame, which any thread may do: see nextRead().
    using Read = std::function<std::optional<Frame>()>;
    /// The next frame as work for another thread: the source takes its place in the stream at
    /// once and returns what reads and decodes it (which may throw as next() does, and returns
    /// the frame), so that ReadAheadSource decodes several frames at a time. nullopt at the end.
    /// By default next() itself, done here: sources whose frames must be decoded one after the
    /// other (videos, cameras, pairing by timestamp).
    virtual std::optional<Read> nextRead();
    /// Number of frames, when known in advance (recorded clips).
    virtual std::optional<std::size_t> frameCount() const { return std::nullopt; }
    /// Nominal frame rate in Hz, used by video sinks; 0 when unknown.
    virtual double frameRate() const { return 0.0; }
    /// One line for logs: kind and location, e.g. "TUM RGB-D sequence data/tum (10 pairs)".
    virtual std::string describe() const = 0;
    // ---- streams ----
    /// True for sources that capture in real time (cameras): they do not end by themselves, and
    /// a consumer slower than the source drops frames rather than queueing them.
    virtual bool isLive() const { return false; }
};

struct SourceOptions {
    /// A TUM folder, a folder of colour images, or a single colour image file.
    std::filesystem::path input;
    /// Depth for `input`: a folder (paired by sorted file name) or a single file. Not needed
    /// for the TUM layout, which names its own depth files.
    std::optional<std::filesystem::path> depth;
    /// Units per metre of 16-bit depth images. Unset: 5000 for the TUM layout and a depth list
    /// (depth.txt), 1000 otherwise.
    std::optional<double> depthScale;
    /// 16-bit depth comes as it was stored, CV_16UC1 with Frame::depthScale (what the filter
    /// uploads as it is); otherwise as CV_32FC1 metres.
    bool depthUnits = false;
    // ---- streams: `input` may also be a camera (/dev/video*), with `depth` a second
    // camera giving Z16 depth; a video file may take a depth folder or depth.txt (by index).
    /// Capture size asked of a camera, pixels (> 0); the driver picks the nearest it has.
    int width = 640;
    int height = 480;
    /// Frame rate asked of a camera, Hz (> 0); the driver picks the nearest it has.
    double fps = 30.0;
    /// Pixel format asked of a colour camera (a V4L2 FourCC name: YUYV, MJPG, NV12, RGB3...);
    /// "" = the fastest it offers among those defocus decodes.
    std::string pixelFormat = {};
    /// A colour camera's YUYV or NV12 frames come as they were captured (Frame::yuv), not as BGR.
    bool yuvColor = false;
};

/// The units per metre openSource reads 16-bit depth at when `options.depthScale` is unset: 5000
/// (TUM's) for a folder in the TUM layout and for a depth list (.txt), 1000 (millimetres) for
/// everything else. README "Depth scales" says why the TUM layout keeps 5000.
double defaultDepthScale(const SourceOptions& options);

/// Opens the source that `options.input` names; throws SourceError with a clear message when
/// it does not exist or cannot be recognised. Its frames' depth is metres unless
/// `options.depthUnits`.
std::unique_ptr<FrameSource> openSource(const SourceOptions& options);

} // namespace defocus
