// SPDX-License-Identifier: LGPL-2.1-or-later
// Focus over the frames of a recorded clip, as --focus and --focus-point ask for it:
//   --focus 1.2                 fixed, metres ('inf' for infinity)
//   --focus auto                the median depth of the centre (or of --focus-point) of the first frame
//   --focus track               follows the scene: the preview's autofocus (critically damped in
//                               dioptres, time constant --tau) stepped with each frame's time
//   --focus 0s:1.2,2s:3.5       a focus pull between keys (TIME s: metres), eased in dioptres
//   --focus-point 320,240       measure at that pixel (a window around it, holes ignored)
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "defocus/Focus.hpp"
#include "defocus/Frame.hpp"

namespace defocus {

/// Keyframed focus: focus distances at times, eased between them in dioptres (1/m), so that a
/// pull from 1 m to infinity spends its time where the picture changes, as a focus puller's hand.
class FocusSchedule {
public:
    struct Key {
        double timeS;  ///< seconds from the clip's first frame
        double focusM; ///< metres; +inf allowed
    };

    /// Parses "0s:1.2,2s:3.5" (times in seconds with an 's', ascending; distances in metres or
    /// 'inf'). Throws std::invalid_argument naming the bad key.
    static FocusSchedule parse(std::string_view text);
    /// True when `text` is meant as keys (holds a ':').
    static bool isKeyed(std::string_view text);

    /// Focus at `timeS`: the first key's before it, the last key's after it, and in between the
    /// dioptres of the two keys around it mixed by smoothstep (3u^2 - 2u^3, u the fraction of the
    /// way from one key to the next): at rest at each key, fastest half way.
    double focusAt(double timeS) const;
    const std::vector<Key>& keys() const { return keys_; }

private:
    std::vector<Key> keys_;
};

/// The depth under pixel `point` of a frame whose colour is `colorSize`: the median of the valid
/// depths in a square of `windowFraction` of the width (at least 5 px) around it, the depth map
/// scaled to the colour size. nullopt when that window holds no valid depth.
std::optional<double> depthAtPoint(const cv::Mat& depthMetres, cv::Size colorSize, cv::Point2d point,
                                   double windowFraction = 0.02);

/// Parses "X,Y" (pixels); throws std::invalid_argument.
cv::Point2d parsePoint(std::string_view text);

/// Focus frame by frame for a clip, from --focus and --focus-point.
class FocusControl {
public:
    /// `focus`: metres, 'inf', 'auto', 'track' or keys. Throws std::invalid_argument.
    FocusControl(const std::string& focus, std::optional<cv::Point2d> point, FocusTrackerOptions autofocus = {});

    /// The focus for `frame`, `timeS` seconds after the clip's first frame and `dtS` after the
    /// previous one. 'auto' measures the first frame with valid depth and keeps it.
    double focusFor(const Frame& frame, double timeS, double dtS);

    /// One line for logs of how the focus is chosen.
    std::string describe() const;
    bool isFixed() const { return mode_ == Mode::Fixed; }
    /// focusFor() will read the next frame's depth: 'auto' until it has measured, 'track' always.
    bool readsDepth() const { return mode_ == Mode::Track || (mode_ == Mode::Auto && !autoM_); }

private:
    enum class Mode { Fixed, Auto, Track, Keyed };
    double measure(const Frame& frame) const;

    Mode mode_ = Mode::Auto;
    double fixedM_ = 2.0;
    std::optional<double> autoM_;
    FocusSchedule schedule_;
    std::optional<cv::Point2d> point_;
    FocusTracker autofocus_;
    bool tracking_ = false;
};

} // namespace defocus
