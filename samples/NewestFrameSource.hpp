// SPDX-License-Identifier: LGPL-2.1-or-later
// A live source read through FrameFeed (LiveLoop.hpp): a capture thread keeps only the newest
// frame, so a consumer slower than the camera gets the newest frame and the camera never waits;
// the frames it replaces are counted. The command line reads a camera this way when it writes to
// a virtual camera (-o /dev/videoN), as the preview does.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "samples/LiveLoop.hpp"
#include "sources/FrameSource.hpp"

namespace defocus {

class NewestFrameSource final : public FrameSource {
public:
    /// Starts capturing from `source` (which must be live) at once. next() gives up, returning
    /// nullopt, once `stopRequested` returns true (checked every 100 ms while waiting).
    NewestFrameSource(std::unique_ptr<FrameSource> source, std::function<bool()> stopRequested);
    ~NewestFrameSource() override;

    /// The newest frame not yet taken, waiting for one; nullopt when the stream ended or a stop
    /// was requested. Rethrows the source's error.
    std::optional<Frame> next() override;
    double frameRate() const override { return source_->frameRate(); }
    std::string describe() const override { return source_->describe(); }
    bool isLive() const override { return true; }

    /// Frames read from the camera, and those replaced before they were taken.
    std::size_t captured() const { return feed_.captured(); }
    std::size_t dropped() const { return feed_.dropped(); }

private:
    std::unique_ptr<FrameSource> source_; // outlives feed_, whose thread reads it
    FrameFeed feed_;
    std::function<bool()> stopRequested_;
};

} // namespace defocus
