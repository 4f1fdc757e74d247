// SPDX-License-Identifier: LGPL-2.1-or-later
// Automatic focus distance from the depth map: a parabolically weighted centre window (or a
// tapped point), smoothed over time by a critically damped spring in dioptres (1/m).
//   defocus-preview data/tum_fr1_rpy              (autofocus on; click = tap to focus; f toggles)
#pragma once

#include <optional>

#include <opencv2/core.hpp>

namespace defocus {

/// Where focus is measured: a window centred on `centre`, spanning `size`, both normalised to
/// the image ([0, 1] of the width and of the height). Parts outside the image are ignored.
struct FocusWindow {
    cv::Point2d centre{0.5, 0.5};
    cv::Size2d size{0.1, 0.1};
};

/// Focus distance for `window` of `depth` (CV_32FC1 metres, any size; invalid pixels as in
/// isValidDepth() are ignored): the weighted mean of 1/z with the separable parabolic weights
/// w(x, y) = (1 - u^2)(1 - v^2), u and v running from -1 to 1 across the window, renormalised
/// over the valid pixels; nullopt when the window holds no valid depth. Returned in metres.
std::optional<double> measureFocus(const cv::Mat& depth, const FocusWindow& window);

/// Seconds between two frames: the difference of their timestamps when both are known (> 0) and
/// it lies in (0, 1] s; otherwise `fallbackS` (use 1 / frame rate).
double frameInterval(double previousTimestamp, double timestamp, double fallbackS);

struct AutofocusSettings {
    /// Side of the centre window, fraction of each axis, (0, 1]. 10 % as in the seed report.
    double windowFraction = 0.10;
    /// Side of the square tap-to-focus region, fraction of the image width, (0, 1]; at least
    /// 3 pixels. 2 % is ~13 px at 640 px: one object, not its surroundings.
    double tapFraction = 0.02;
    /// Time constant tau of the critically damped spring, seconds, >= 0 (0 jumps at once). From
    /// rest a step reaches 95 % of its way in 4.7 tau and 99 % in 6.6 tau, with no overshoot.
    double timeConstantS = 0.25;
    /// Dead band, dioptres (1/m), >= 0: the target moves only when the measurement leaves this
    /// band around it, so sensor noise does not make the focus hunt. 0.02 D is 2 cm at 1 m and
    /// 18 cm at 3 m; for the default 50 mm f/2 lens across 640 px (36 mm sensor) the CoC
    /// changes by A f W / s = 25 mm * 50 mm * 640 px / 36 mm = 22 px per dioptre, so 0.02 D is
    /// under half a pixel of blur: a change nobody can see.
    double deadBandDioptres = 0.02;
};

/// The focus controller. One per stream; works the same for clips and live input: it is
/// stepped with each frame's dt (frameInterval()), or with wall-clock time while a frame is held.
class Autofocus {
public:
    explicit Autofocus(AutofocusSettings settings = {}, double initialFocusM = 2.0);

    /// Measures the focus region of `depth` (when it has valid depth; otherwise the target
    /// stays) and moves the focus `dtS` seconds toward it. The stream's first valid measurement
    /// is taken at once rather than swept to from `initialFocusM`. Returns the focus, metres.
    double update(const cv::Mat& depth, double dtS);
    /// Moves the focus `dtS` seconds toward the current target with no new measurement.
    double advance(double dtS);
    /// Measures `depth` once and makes it the target (no step): for a tap while following is
    /// off. Returns false, keeping the target, when the region has no valid depth.
    bool retarget(const cv::Mat& depth);

    /// Measure around `point` (normalised [0, 1] image coordinates) from now on, in a square of
    /// tapFraction of the width; `aspect` = image width / height.
    void tap(cv::Point2d point, double aspect);
    /// Back to the centre window.
    void recentre();
    /// Sets the focus (and target) at once, at rest: manual focus.
    void setFocus(double focusM);

    /// Current focus distance, metres (+inf at 0 D).
    double focusM() const;
    /// Where the spring is heading, metres.
    double targetM() const;
    /// True when at the target and at rest (within 1e-4 D and 1e-4 D/s).
    bool settled() const;
    /// The region measured, normalised.
    const FocusWindow& window() const { return window_; }
    bool tapped() const { return tapped_; }
    const AutofocusSettings& settings() const { return settings_; }

private:
    AutofocusSettings settings_;
    FocusWindow window_;
    bool tapped_ = false;
    bool measuredOnce_ = false; ///< the first valid measurement is taken at once, not swept to
    double position_;     ///< focus, dioptres
    double velocity_ = 0; ///< dioptres per second
    double target_;       ///< dioptres
};

} // namespace defocus
