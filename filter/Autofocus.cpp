// SPDX-License-Identifier: LGPL-2.1-or-later
// Autofocus: centre-weighted focus measurement (after the seed report 003: a small centre view,
// parabolic weights, separable) and a critically damped spring in dioptres.
#include "filter/Autofocus.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

#include "filter/DepthPrep.hpp"

namespace defocus {
namespace {

/// Pixels [first, first + weights.size()) of an axis `length` long covered by a window centred
/// at `centre` px with half-size `half` px, and their parabolic weights 1 - u^2, u = offset /
/// half in (-1, 1) at pixel centres: largest in the middle, falling to 0 at the edges.
struct AxisWeights {
    int first = 0;
    std::vector<double> weights;
};

AxisWeights axisWeights(double centre, double half, int length)
{
    AxisWeights axis;
    half = std::max(half, 1.5); // at least three pixels
    const int begin = std::max(0, static_cast<int>(std::floor(centre - half)));
    const int end = std::min(length, static_cast<int>(std::ceil(centre + half)));
    axis.first = begin;
    for (int i = begin; i < end; ++i) {
        const double u = (static_cast<double>(i) + 0.5 - centre) / half;
        axis.weights.push_back(std::max(0.0, 1.0 - u * u));
    }
    return axis;
}

constexpr double kSettledDioptres = 1e-4;

double toDioptres(double metres)
{
    return std::isinf(metres) ? 0.0 : 1.0 / metres;
}

double toMetres(double dioptres)
{
    return dioptres > 0.0 ? 1.0 / dioptres : std::numeric_limits<double>::infinity();
}

} // namespace

std::optional<double> measureFocus(const cv::Mat& depth, const FocusWindow& window)
{
    if (depth.empty())
        return std::nullopt;
    CV_Assert(depth.type() == CV_32FC1);
    const AxisWeights columns = axisWeights(window.centre.x * depth.cols, 0.5 * window.size.width * depth.cols,
                                            depth.cols);
    const AxisWeights rows = axisWeights(window.centre.y * depth.rows, 0.5 * window.size.height * depth.rows,
                                         depth.rows);
    // Why the mean of 1/z: the thin-lens CoC is c(z) = K |1/z_f - 1/z| (K nearly constant for
    // z_f >> f), so the focus minimising the weighted mean squared CoC over the window,
    // d/d(1/z_f) sum w (1/z_f - 1/z)^2 = 0, is 1/z_f = sum w/z / sum w. It also keeps a window
    // straddling a near and a far surface from focusing on the empty space halfway in metres
    // any more than the blur itself does.
    // Separable: each row is reduced with the column weights, then the rows with the row
    // weights. Invalid pixels drop out of both the sum and the weight, which renormalises the
    // kernel over the valid pixels.
    double sum = 0.0, weight = 0.0;
    for (std::size_t r = 0; r < rows.weights.size(); ++r) {
        const float* row = depth.ptr<float>(rows.first + static_cast<int>(r));
        double rowSum = 0.0, rowWeight = 0.0;
        for (std::size_t c = 0; c < columns.weights.size(); ++c) {
            const float z = row[columns.first + static_cast<int>(c)];
            if (!isValidDepth(z))
                continue;
            rowSum += columns.weights[c] / static_cast<double>(z);
            rowWeight += columns.weights[c];
        }
        sum += rows.weights[r] * rowSum;
        weight += rows.weights[r] * rowWeight;
    }
    if (!(weight > 0.0) || !(sum > 0.0))
        return std::nullopt;
    return weight / sum;
}

double frameInterval(double previousTimestamp, double timestamp, double fallbackS)
{
    const double dt = timestamp - previousTimestamp;
    if (previousTimestamp > 0.0 && timestamp > 0.0 && dt > 0.0 && dt <= 1.0)
        return dt;
    return fallbackS;
}

Autofocus::Autofocus(AutofocusSettings settings, double initialFocusM)
    : settings_(settings),
      window_{{0.5, 0.5}, {settings.windowFraction, settings.windowFraction}},
      position_(toDioptres(initialFocusM)),
      target_(position_)
{
    assert(settings.windowFraction > 0.0 && settings.windowFraction <= 1.0);
    assert(settings.tapFraction > 0.0 && settings.tapFraction <= 1.0);
    assert(settings.timeConstantS >= 0.0 && settings.deadBandDioptres >= 0.0);
    assert(initialFocusM > 0.0);
}

bool Autofocus::retarget(const cv::Mat& depth)
{
    const std::optional<double> measured = measureFocus(depth, window_);
    if (!measured)
        return false; // no valid depth here: keep what we have
    const double dioptres = toDioptres(*measured);
    if (!measuredOnce_) {
        // The first measurement of a stream is taken as it is: no sweep from the default focus.
        measuredOnce_ = true;
        position_ = target_ = dioptres;
        velocity_ = 0.0;
    } else if (std::abs(dioptres - target_) > settings_.deadBandDioptres) {
        target_ = dioptres;
    }
    return true;
}

double Autofocus::update(const cv::Mat& depth, double dtS)
{
    retarget(depth);
    return advance(dtS);
}

double Autofocus::advance(double dtS)
{
    if (!(dtS > 0.0) || !std::isfinite(dtS))
        return focusM();
    const double tau = settings_.timeConstantS;
    if (tau <= 0.0) {
        position_ = target_;
        velocity_ = 0.0;
        return focusM();
    }
    // Critically damped spring x'' = w^2 (T - x) - 2 w x', w = 1 / tau, solved exactly for a
    // target T held over the step, so any dt is stable: with e = x - T,
    //   e(t) = (e0 + (v0 + w e0) t) exp(-w t),  v(t) = (v0 - w (v0 + w e0) t) exp(-w t).
    // From rest, e(t) / e0 = (1 + w t) exp(-w t) falls monotonically: no overshoot, no ringing.
    const double w = 1.0 / tau;
    const double e0 = position_ - target_;
    const double c = velocity_ + w * e0;
    const double decay = std::exp(-w * dtS);
    position_ = target_ + (e0 + c * dtS) * decay;
    velocity_ = (velocity_ - w * c * dtS) * decay;
    position_ = std::max(position_, 0.0); // 0 D is infinity; nothing lies beyond
    return focusM();
}

void Autofocus::tap(cv::Point2d point, double aspect)
{
    window_.centre = {std::clamp(point.x, 0.0, 1.0), std::clamp(point.y, 0.0, 1.0)};
    window_.size = {settings_.tapFraction, settings_.tapFraction * (aspect > 0.0 ? aspect : 1.0)};
    tapped_ = true;
}

void Autofocus::recentre()
{
    window_ = {{0.5, 0.5}, {settings_.windowFraction, settings_.windowFraction}};
    tapped_ = false;
}

void Autofocus::setFocus(double focusM)
{
    assert(focusM > 0.0);
    position_ = target_ = toDioptres(focusM);
    velocity_ = 0.0;
    measuredOnce_ = true;
}

double Autofocus::focusM() const
{
    return toMetres(position_);
}

double Autofocus::targetM() const
{
    return toMetres(target_);
}

bool Autofocus::settled() const
{
    return std::abs(position_ - target_) < kSettledDioptres && std::abs(velocity_) < kSettledDioptres;
}

} // namespace defocus
