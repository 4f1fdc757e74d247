// SPDX-License-Identifier: LGPL-2.1-or-later
// NewestFrameSource: FrameFeed's newest-frame slot behind the FrameSource contract.
#include "samples/NewestFrameSource.hpp"

#include <chrono>
#include <utility>

namespace defocus {

NewestFrameSource::NewestFrameSource(std::unique_ptr<FrameSource> source, std::function<bool()> stopRequested)
    : source_(std::move(source)), feed_(*source_, true), stopRequested_(std::move(stopRequested))
{
}

NewestFrameSource::~NewestFrameSource()
{
    feed_.stop();
}

std::optional<Frame> NewestFrameSource::next()
{
    while (!stopRequested_()) {
        // Short waits, so that a stop request is seen even while the camera is silent.
        if (std::optional<FedFrame> fed = feed_.next(std::chrono::milliseconds(100)))
            return std::move(fed->frame);
        if (feed_.ended())
            return std::nullopt;
    }
    return std::nullopt;
}

} // namespace defocus
