// SPDX-License-Identifier: LGPL-2.1-or-later
// Colour from one source, depth from another: a fixed depth image, a depth sequence (folder or
// TUM depth.txt) paired by index or by timestamp, or a live Z16 node paired by timestamp.
//   defocus clip.mp4 --depth depth_dir/ -o out.mp4          (depth image k for video frame k)
//   defocus /dev/video0 --depth depth.png -o out.mp4        (one depth for a fixed camera)
//   defocus /dev/video0 --depth /dev/video2 -o out.mp4      (RealSense-style colour + Z16 nodes)
// Depth keeps its own size: the pipeline resizes it to the colour size with nearest-neighbour
// sampling, which never blends the depths of two sides of an edge.
#pragma once

#include <cstddef>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "sources/FrameSource.hpp"
#include "sources/ImageIO.hpp"
#include "sources/V4l2Source.hpp"

namespace defocus {

/// One depth image handed to a colour frame.
struct DepthSample {
    StoredDepth depth; ///< as stored, its own size
    std::string name; ///< for messages, e.g. "depth/000012.png" or "video2#40"
};

/// Where the depth for each colour frame comes from.
class DepthProvider {
public:
    virtual ~DepthProvider() = default;
    /// The depth for `color`, or nullopt when none pairs with it (the frame then passes through
    /// in focus). Throws SourceError when a depth image cannot be read or a depth camera fails.
    virtual std::optional<DepthSample> depthFor(const Frame& color) = 0;
    /// Number of depth images, when known.
    virtual std::optional<std::size_t> count() const { return std::nullopt; }
    virtual std::string describe() const = 0;
};

/// One depth image for every frame: a fixed camera looking at a static scene.
class StaticDepth final : public DepthProvider {
public:
    /// Reads the image at once (SourceError naming it when it cannot be read).
    StaticDepth(std::filesystem::path file, double unitsPerMetre);
    std::optional<DepthSample> depthFor(const Frame& color) override;
    std::optional<std::size_t> count() const override { return 1; }
    std::string describe() const override;

private:
    std::filesystem::path file_;
    StoredDepth depth_;
};

/// How a depth sequence is matched to colour frames.
struct DepthPairing {
    enum class Mode {
        Index,     ///< depth image k for colour frame k (Frame::index)
        Timestamp, ///< the depth image nearest in time, within maxGap
    };
    Mode mode = Mode::Index;
    /// Timestamp mode: a colour frame and a depth image further apart than this are not paired,
    /// seconds (>= 0). 20 ms is the TUM benchmark's own associate.py tolerance.
    double maxGap = 0.020;
    /// Timestamp mode: measure both clocks from their own first entry (true), so that a video's
    /// 0-based times meet a depth list's absolute times; false compares the times as they are.
    bool alignStarts = true;
};

/// A sequence of depth images on disk, read lazily (one image at a time, the last one cached).
class DepthSequence final : public DepthProvider {
public:
    struct Entry {
        std::filesystem::path file;
        std::optional<double> time; ///< seconds, when the sequence has times
    };

    /// A folder of depth images (png, tif, tiff, exr) in natural name order ("d2" before "d10").
    /// File names that are all numbers ("1305031250.253735.png") are read as times in seconds,
    /// so the folder can also pair by timestamp. Throws SourceError for an empty folder, or for
    /// timestamp pairing when the names are not times.
    static std::unique_ptr<DepthSequence> fromFolder(const std::filesystem::path& folder,
                                                     double unitsPerMetre, DepthPairing pairing);
    /// A TUM-style depth.txt ("time file" lines; files relative to the list's folder). Throws
    /// SourceError "LIST:LINE: ..." for a bad line or a listed file that does not exist.
    static std::unique_ptr<DepthSequence> fromList(const std::filesystem::path& list,
                                                   double unitsPerMetre, DepthPairing pairing);

    DepthSequence(std::vector<Entry> entries, double unitsPerMetre, DepthPairing pairing,
                  std::string origin);

    std::optional<DepthSample> depthFor(const Frame& color) override;
    std::optional<std::size_t> count() const override { return entries_.size(); }
    std::string describe() const override;
    const DepthPairing& pairing() const { return pairing_; }
    /// The entry `color` pairs with, without reading it (nullopt: none).
    std::optional<std::size_t> match(const Frame& color);

private:
    std::vector<Entry> entries_; // sorted by time in timestamp mode
    double unitsPerMetre_;
    DepthPairing pairing_;
    std::string origin_;
    std::optional<double> firstColorTime_;
    std::optional<std::size_t> cachedIndex_;
    StoredDepth cached_;
};

/// Depth from a second, live V4L2 node (Z16), paired with each colour frame by capture time: the
/// depth frame nearest in time within maxGap, waiting at most maxGap for one that is yet to come.
/// Both nodes' times are on CLOCK_MONOTONIC (V4l2Source), so no offset is needed.
class V4l2DepthStream final : public DepthProvider {
public:
    /// `maxGap` <= 0: half the depth node's frame interval, at least 20 ms.
    explicit V4l2DepthStream(std::unique_ptr<V4l2Source> depth, double maxGap = 0.0);
    std::optional<DepthSample> depthFor(const Frame& color) override;
    std::string describe() const override;
    double maxGap() const { return maxGap_; }
    const V4l2Source& source() const { return *depth_; }

private:
    std::unique_ptr<V4l2Source> depth_;
    double maxGap_;
    std::deque<Frame> recent_; // depth frames by time, oldest first
    double lastArrival_ = 0.0; // steady clock, seconds
};

/// A colour source with its depth from a DepthProvider.
class PairedSource final : public FrameSource {
public:
    /// `color`'s own depth, if any, is replaced.
    PairedSource(std::unique_ptr<FrameSource> color, std::unique_ptr<DepthProvider> depth);

    /// Throws SourceError when either side fails, or when a depth has another aspect ratio than
    /// its colour frame (naming both). Colour frames with no depth pass through in focus, with
    /// one warning.
    std::optional<Frame> next() override;
    std::optional<std::size_t> frameCount() const override { return color_->frameCount(); }
    double frameRate() const override { return color_->frameRate(); }
    bool isLive() const override { return color_->isLive(); }
    std::string describe() const override;
    /// Colour frames that got no depth so far.
    std::size_t unpairedFrames() const { return unpaired_; }

private:
    std::unique_ptr<FrameSource> color_;
    std::unique_ptr<DepthProvider> depth_;
    std::size_t unpaired_ = 0;
};

} // namespace defocus
