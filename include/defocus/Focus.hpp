// SPDX-License-Identifier: LGPL-2.1-or-later
// Focus from depth, for programs that choose the focus themselves (a live preview with tap to
// focus, a clip that follows its subject) and hand it to the Filter as Lens::focusM:
//   defocus::FocusTracker tracker;                        // the centre window, tau 0.25 s
//   tracker.tap({0.7, 0.4}, 640.0 / 480.0);               // measure around a tapped point instead
//   settings.lens.focusM = tracker.update(depthMetres, 1.0 / 30.0);
//   filter.setSettings(settings);
// The Filter's own AutofocusOptions::Mode::Follow is this tracker on the centre window.
// Threads: a FocusTracker is plain data, used from one thread at a time; the functions may be
// called from any thread.
#pragma once

#include <memory>
#include <optional>

#include <opencv2/core.hpp>

#include "defocus/Export.hpp"

namespace defocus {

/// Where focus is measured: a window centred on `centre`, spanning `size`, both as fractions of
/// the image ([0, 1] of its width and of its height). Parts outside the image are ignored.
struct FocusRegion {
    cv::Point2d centre{0.5, 0.5};
    cv::Size2d size{0.1, 0.1};
};

struct FocusTrackerOptions {
    /// Side of the centre window, fraction of each axis, (0, 1]. Default 0.1.
    double windowFraction = 0.10;
    /// Side of the square measured around a tapped point, fraction of the image width, (0, 1];
    /// at least 3 pixels. Default 0.02 (~13 px at 640 px: one object, not its surroundings).
    double tapFraction = 0.02;
    /// The spring's time constant, seconds, >= 0 (0 jumps at once): a step reaches 95 % of its
    /// way in 4.7 time constants, with no overshoot. Default 0.25.
    double timeConstantS = 0.25;
    /// Dead band, dioptres (1/m), >= 0: the target moves only when the measurement leaves this
    /// band around it, so sensor noise does not make the focus hunt. Default 0.02.
    double deadBandDioptres = 0.02;
};

/// A focus that follows the depth of a region: the weighted mean of 1/depth over the region
/// (parabolic weights, holes ignored), reached by a critically damped spring in dioptres. The
/// stream's first valid measurement is taken at once. Depth images are CV_32FC1 metres, any
/// size; 0, NaN and infinities are holes.
class DEFOCUS_API FocusTracker {
public:
    explicit FocusTracker(const FocusTrackerOptions& options = {}, double initialFocusM = 2.0);
    ~FocusTracker();
    FocusTracker(const FocusTracker&);
    FocusTracker& operator=(const FocusTracker&);
    FocusTracker(FocusTracker&&) noexcept;
    FocusTracker& operator=(FocusTracker&&) noexcept;

    /// Measures the region of `depthMetres` (the target stays where it has no valid depth) and
    /// moves the focus `dtS` seconds toward the target. Returns the focus, metres.
    double update(const cv::Mat& depthMetres, double dtS);
    /// Moves the focus `dtS` seconds toward the target with no new measurement (a held frame).
    double advance(double dtS);
    /// Measures `depthMetres` once and makes it the target, without moving: for a tap while the
    /// tracker is not updated. False, with the target kept, where the region has no valid depth.
    bool retarget(const cv::Mat& depthMetres);
    /// Measures around `point` (fractions of the image) from now on; `aspect` = width / height.
    void tap(cv::Point2d point, double aspect);
    /// Measures the centre window again.
    void recentre();
    /// Focus and target at `focusM` (metres, +inf allowed), at rest: manual focus.
    void setFocus(double focusM);

    /// Current focus, metres (+inf at 0 dioptres).
    double focusM() const;
    /// Where the spring is heading, metres.
    double targetM() const;
    /// At the target and at rest.
    bool settled() const;
    /// The region is a tapped point, not the centre window.
    bool tapped() const;
    FocusRegion region() const;
    const FocusTrackerOptions& options() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The command line's `--focus auto`: the median valid depth of the central `windowFraction` of
/// each axis of `depthMetres` (CV_32FC1); nullopt where that window has none.
DEFOCUS_API std::optional<double> medianCentreDepth(const cv::Mat& depthMetres, double windowFraction = 0.1);

/// Seconds between two frames: the difference of their timestamps when both are known (> 0)
/// and it lies in (0, 1] s; otherwise `fallbackS` (1 / the frame rate).
DEFOCUS_API double secondsBetweenFrames(double previousTimestampS, double timestampS, double fallbackS);

} // namespace defocus
