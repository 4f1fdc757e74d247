// SPDX-License-Identifier: LGPL-2.1-or-later
// libdefocus: the public FocusTracker (include/defocus/Focus.hpp) over the filter's Autofocus.
#include "defocus/Focus.hpp"

#include <cmath>
#include <limits>

#include "filter/Autofocus.hpp"
#include "filter/DepthPrep.hpp"

namespace defocus {

namespace {

AutofocusSettings toAutofocus(const FocusTrackerOptions& options)
{
    AutofocusSettings out;
    out.windowFraction = options.windowFraction;
    out.tapFraction = options.tapFraction;
    out.timeConstantS = options.timeConstantS;
    out.deadBandDioptres = options.deadBandDioptres;
    return out;
}

} // namespace

struct FocusTracker::Impl {
    FocusTrackerOptions options;
    Autofocus autofocus;
};

FocusTracker::FocusTracker(const FocusTrackerOptions& options, double initialFocusM)
    : impl_(std::make_unique<Impl>(Impl{options, Autofocus(toAutofocus(options), initialFocusM)}))
{
}

FocusTracker::~FocusTracker() = default;
FocusTracker::FocusTracker(const FocusTracker& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
FocusTracker& FocusTracker::operator=(const FocusTracker& other)
{
    if (this != &other)
        impl_ = std::make_unique<Impl>(*other.impl_);
    return *this;
}
FocusTracker::FocusTracker(FocusTracker&&) noexcept = default;
FocusTracker& FocusTracker::operator=(FocusTracker&&) noexcept = default;

double FocusTracker::update(const cv::Mat& depthMetres, double dtS)
{
    return impl_->autofocus.update(depthMetres, dtS);
}

double FocusTracker::advance(double dtS)
{
    return impl_->autofocus.advance(dtS);
}

bool FocusTracker::retarget(const cv::Mat& depthMetres)
{
    return impl_->autofocus.retarget(depthMetres);
}

void FocusTracker::tap(cv::Point2d point, double aspect)
{
    impl_->autofocus.tap(point, aspect);
}

void FocusTracker::recentre()
{
    impl_->autofocus.recentre();
}

void FocusTracker::setFocus(double focusM)
{
    impl_->autofocus.setFocus(focusM);
}

double FocusTracker::focusM() const
{
    return impl_->autofocus.focusM();
}

double FocusTracker::targetM() const
{
    return impl_->autofocus.targetM();
}

bool FocusTracker::settled() const
{
    return impl_->autofocus.settled();
}

bool FocusTracker::tapped() const
{
    return impl_->autofocus.tapped();
}

FocusRegion FocusTracker::region() const
{
    const FocusWindow& window = impl_->autofocus.window();
    return {window.centre, window.size};
}

const FocusTrackerOptions& FocusTracker::options() const
{
    return impl_->options;
}

std::optional<double> medianCentreDepth(const cv::Mat& depthMetres, double windowFraction)
{
    const float median = centreDepth(depthMetres, windowFraction, std::numeric_limits<float>::quiet_NaN());
    if (!std::isfinite(median))
        return std::nullopt;
    return median;
}

double secondsBetweenFrames(double previousTimestampS, double timestampS, double fallbackS)
{
    return frameInterval(previousTimestampS, timestampS, fallbackS);
}

} // namespace defocus
