// SPDX-License-Identifier: LGPL-2.1-or-later
// Focus over a clip: fixed, first-frame auto, tracking autofocus and keyframed pulls.
#include "samples/FocusSchedule.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include <fmt/format.h>


namespace defocus {
namespace {

std::string_view trim(std::string_view text)
{
    while (!text.empty() && text.front() == ' ')
        text.remove_prefix(1);
    while (!text.empty() && text.back() == ' ')
        text.remove_suffix(1);
    return text;
}

std::optional<double> number(std::string_view text)
{
    text = trim(text);
    if (text == "inf")
        return std::numeric_limits<double>::infinity();
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
        return std::nullopt;
    return value;
}

double dioptres(double metres)
{
    return std::isinf(metres) ? 0.0 : 1.0 / metres;
}

} // namespace

bool FocusSchedule::isKeyed(std::string_view text)
{
    return text.find(':') != std::string_view::npos;
}

FocusSchedule FocusSchedule::parse(std::string_view text)
{
    FocusSchedule schedule;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t comma = std::min(text.find(',', start), text.size());
        const std::string_view key = trim(text.substr(start, comma - start));
        const std::size_t colon = key.find(':');
        const std::string_view time = colon == std::string_view::npos ? key : trim(key.substr(0, colon));
        const auto bad = [&](const char* why) {
            return std::invalid_argument(fmt::format("--focus key '{}': {} (keys look like 0s:1.2,2s:3.5: seconds "
                                                     "with an 's', then metres or 'inf')",
                                                     key, why));
        };
        if (colon == std::string_view::npos)
            throw bad("no ':' between time and distance");
        if (time.empty() || time.back() != 's')
            throw bad("the time needs an 's' (seconds)");
        const auto seconds = number(time.substr(0, time.size() - 1));
        const auto metres = number(key.substr(colon + 1));
        if (!seconds || *seconds < 0.0)
            throw bad("the time is not a number of seconds >= 0");
        if (!metres || !(*metres > 0.0))
            throw bad("the distance is not a positive number of metres or 'inf'");
        if (!schedule.keys_.empty() && *seconds <= schedule.keys_.back().timeS)
            throw bad("times must rise from key to key");
        schedule.keys_.push_back({*seconds, *metres});
        start = comma + 1;
    }
    return schedule;
}

double FocusSchedule::focusAt(double timeS) const
{
    if (keys_.empty())
        return 2.0;
    if (timeS <= keys_.front().timeS)
        return keys_.front().focusM;
    if (timeS >= keys_.back().timeS)
        return keys_.back().focusM;
    const auto next = std::upper_bound(keys_.begin(), keys_.end(), timeS,
                                       [](double t, const Key& key) { return t < key.timeS; });
    const Key& b = *next;
    const Key& a = *(next - 1);
    const double u = (timeS - a.timeS) / (b.timeS - a.timeS);
    const double eased = u * u * (3.0 - 2.0 * u);
    const double d = dioptres(a.focusM) + eased * (dioptres(b.focusM) - dioptres(a.focusM));
    return d > 0.0 ? 1.0 / d : std::numeric_limits<double>::infinity();
}

std::optional<double> depthAtPoint(const cv::Mat& depthMetres, cv::Size colorSize, cv::Point2d point,
                                   double windowFraction)
{
    if (depthMetres.empty() || depthMetres.type() != CV_32FC1 || colorSize.width <= 0 || colorSize.height <= 0)
        return std::nullopt;
    const double sx = static_cast<double>(depthMetres.cols) / colorSize.width;
    const double sy = static_cast<double>(depthMetres.rows) / colorSize.height;
    const int half = std::max(2, static_cast<int>(std::lround(windowFraction * depthMetres.cols / 2.0)));
    const int cx = static_cast<int>(std::floor(point.x * sx));
    const int cy = static_cast<int>(std::floor(point.y * sy));
    std::vector<float> valid;
    for (int y = std::max(0, cy - half); y <= std::min(depthMetres.rows - 1, cy + half); ++y)
        for (int x = std::max(0, cx - half); x <= std::min(depthMetres.cols - 1, cx + half); ++x) {
            const float d = depthMetres.at<float>(y, x);
            if (std::isfinite(d) && d > 0.0f)
                valid.push_back(d);
        }
    if (valid.empty())
        return std::nullopt;
    const auto middle = valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2);
    std::nth_element(valid.begin(), middle, valid.end());
    return *middle;
}

cv::Point2d parsePoint(std::string_view text)
{
    const std::size_t comma = text.find(',');
    const auto x = comma == std::string_view::npos ? std::nullopt : number(text.substr(0, comma));
    const auto y = comma == std::string_view::npos ? std::nullopt : number(text.substr(comma + 1));
    if (!x || !y || *x < 0.0 || *y < 0.0 || std::isinf(*x) || std::isinf(*y))
        throw std::invalid_argument(fmt::format("--focus-point '{}' is not X,Y in pixels (e.g. 320,240)", text));
    return {*x, *y};
}

FocusControl::FocusControl(const std::string& focus, std::optional<cv::Point2d> point, FocusTrackerOptions autofocus)
    : point_(point), autofocus_(autofocus)
{
    if (focus == "auto") {
        mode_ = Mode::Auto;
    } else if (focus == "track") {
        mode_ = Mode::Track;
    } else if (FocusSchedule::isKeyed(focus)) {
        mode_ = Mode::Keyed;
        schedule_ = FocusSchedule::parse(focus);
    } else if (const auto metres = number(focus); metres && *metres > 0.0) {
        mode_ = Mode::Fixed;
        fixedM_ = *metres;
    } else {
        throw std::invalid_argument(fmt::format(
            "--focus '{}' is not metres, 'inf', 'auto', 'track' or keys such as 0s:1.2,2s:3.5", focus));
    }
    if (point_ && (mode_ == Mode::Fixed || mode_ == Mode::Keyed))
        throw std::invalid_argument("--focus-point measures the focus: use it with --focus auto or track");
}

double FocusControl::measure(const Frame& frame) const
{
    if (point_)
        return depthAtPoint(depthMetres(frame), colorSize(frame), *point_).value_or(std::numeric_limits<double>::quiet_NaN());
    return medianCentreDepth(depthMetres(frame), 0.1).value_or(std::numeric_limits<double>::quiet_NaN());
}

double FocusControl::focusFor(const Frame& frame, double timeS, double dtS)
{
    switch (mode_) {
    case Mode::Fixed: return fixedM_;
    case Mode::Keyed: return schedule_.focusAt(timeS);
    case Mode::Auto:
        if (!autoM_) {
            const double measured = measure(frame);
            if (std::isfinite(measured) && measured > 0.0)
                autoM_ = measured;
        }
        return autoM_.value_or(2.0); // no valid depth yet: 2 m, as centreDepth's fallback
    case Mode::Track:
        if (point_) {
            const cv::Size size = colorSize(frame);
            if (!tracking_ && size.width > 0 && size.height > 0)
                autofocus_.tap({point_->x / size.width, point_->y / size.height},
                               static_cast<double>(size.width) / size.height);
        }
        tracking_ = true;
        return autofocus_.update(depthMetres(frame), dtS);
    }
    return fixedM_;
}

std::string FocusControl::describe() const
{
    const std::string where = point_ ? fmt::format("pixel {:g},{:g}", point_->x, point_->y) : std::string("the centre");
    switch (mode_) {
    case Mode::Fixed: return fmt::format("fixed at {:g} m", fixedM_);
    case Mode::Auto: return fmt::format("auto: median depth of {} of the first frame", where);
    case Mode::Track:
        return fmt::format("track: follows {} (time constant {:g} s)", where, autofocus_.options().timeConstantS);
    case Mode::Keyed: return fmt::format("keyed: {} keys, eased in dioptres", schedule_.keys().size());
    }
    return {};
}

} // namespace defocus
