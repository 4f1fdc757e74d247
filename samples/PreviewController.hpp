// SPDX-License-Identifier: LGPL-2.1-or-later
// What defocus-preview's keys and clicks do: the live controls they change (lens, view, focus
// requests, pause, quit), the lens each frame is rendered with, and the HUD's text and marks,
// handed to the window (sinks/DisplaySink.hpp) to draw. The preview loop reads the controls
// every frame. Keys: kKeyHelp below, docs/preview.md.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "defocus/Filter.hpp"
#include "defocus/Focus.hpp"
#include "defocus/Settings.hpp"
#include "sinks/DisplaySink.hpp"

namespace defocus {

/// What the keys and the mouse change; the preview loop reads it before every frame. Lives on
/// the thread that runs the window (highgui is single-threaded), so it needs no lock.
struct LiveControls {
    /// f-number, max CoC, model, focal length and sensor; focusM is not used (the focus comes
    /// from the FocusTracker) and nearM/farM come from the ratios below.
    Lens lens;
    /// Focal-range model: near limit = focus * nearRatio, (0, 1). Default 0.5 (1 m at 2 m).
    double nearRatio = 0.5;
    /// Focal-range model: far limit = focus * farRatio, (1, +inf). Default 3 (6 m at 2 m).
    double farRatio = 3.0;
    Settings::View view = Settings::View::Composite;
    /// Measure the focus region every frame (f). Off: the focus stays where it is, taps move it.
    bool autofocus = true;
    /// Outline the tiles that need blur (t).
    bool tileMap = false;
    /// Hold the current frame (space); a live source keeps capturing and is not counted as
    /// dropping while paused.
    bool paused = false;
    /// q, Esc, the window closed, or Ctrl-C.
    bool quit = false;
    /// A click not yet served: the point, normalised [0, 1] image coordinates. Cleared by the loop.
    std::optional<cv::Point2d> tap;
    /// 'c' or a right click not yet served: measure the centre window again. Cleared by the loop.
    bool recentre = false;
    /// Bumped by every change that alters the picture, so a held frame is rendered again.
    std::uint64_t revision = 0;
};

/// Keys, one line, for the HUD and --help.
inline constexpr const char* kKeyHelp =
    "1-5 lab views, 6 depth, 7 CoC | +/- f-number | [ ] max CoC | j/l focal range | m model | "
    "b blades | r rotate aperture | o oval | "
    "f autofocus | c centre | t tiles | space pause | s screenshot | q quit | click: focus";

/// What applying a key did, for the log and the HUD.
struct KeyOutcome {
    bool handled = false;
    std::string message;          ///< e.g. "f/2.8"; empty for keys with nothing to say
    std::vector<std::string> issues; ///< clamps, e.g. "--f-number must be between 0.7 and 64, not 71.8"
};

/// Applies one key as cv::waitKey() returns it (ASCII; 27 = Esc). The f-number moves by 1/3
/// stop (x 2^(1/6)) on the standard scale, max CoC by 2 px (0.5 px below 4 px), the focal range
/// by x 1.25 each side (j wider, l narrower, switching to the focal-range model). Impossible
/// values are clamped by defocus::check(settings, true), judged at `focusM`, with the issue
/// returned. 's'
/// is PreviewController's (the window saves its picture), not handled here.
KeyOutcome applyKey(LiveControls& controls, int key, double focusM);

/// The lens for one frame: the controls with `focusM` and the focal-range limits from the
/// ratios, clamped by defocus::check(settings, true); what was clamped goes to `issues` when given.
Lens lensFor(const LiveControls& controls, double focusM, std::vector<std::string>* issues = nullptr);

/// What the HUD shows besides the controls.
struct HudStatus {
    double focusM = 2.0;       ///< focus in use, metres
    double targetM = 2.0;      ///< where autofocus is heading, metres
    bool autofocus = true;
    bool tapped = false;       ///< the focus region is a tapped point, not the centre
    FocusRegion focusWindow;   ///< drawn as corner marks on the frame
    Lens lens;                 ///< as used for the frame (after clamping)
    Settings::View view = Settings::View::Composite;
    double fps = 0.0;          ///< new frames shown per second, recent average
    double latencyMs = 0.0;    ///< capture (or read) to display, recent average
    std::size_t dropped = 0;   ///< live frames replaced before processing
    std::size_t frameIndex = 0;
    bool paused = false;
    bool live = false;
    bool ended = false;        ///< a recorded source has no more frames; the last one is held
    Timings timings;
    std::vector<Timings::Pass> gpu; ///< last known GPU time per pass (timings.gpu arrives a frame late)
    std::string message;       ///< a transient line (the last key's effect or a warning)
    bool warning = false;      ///< `message` is a warning (drawn in orange)
};

/// The HUD the window draws for `status`: four lines of figures, then `message` or the key
/// help; the focus window as marks (green while autofocus follows); when `tileMap` is given, the
/// tiles its Plan::tileMap marks as blurred as outlines.
Hud hudFor(const HudStatus& status, const Plan* tileMap = nullptr);

/// Serves the window's events: keys through applyKey ('s' saves a screenshot), a left click
/// taps to focus there, a right click recentres, a closed window quits. Each effect is logged
/// and shown on the HUD's last line for 4 s.
class PreviewController {
public:
    explicit PreviewController(LiveControls& controls) : controls_(controls) {}

    /// Handles every event `window` gathered since the last call.
    void serve(DisplaySink& window);
    /// Handles one event; `window` (for 's') may be null, and then 's' does nothing.
    void handle(const WindowEvent& event, DisplaySink* window);
    /// Current focus, for judging clamps of keys (set by the loop).
    void setFocusForKeys(double focusM) { focusForKeys_ = focusM; }
    /// hudFor(status, tileMap), with the last effect noted when `status` has no message of its own
    /// and the effect is under 4 s old.
    Hud hud(const HudStatus& status, const Plan* tileMap = nullptr) const;

private:
    using Clock = std::chrono::steady_clock;
    void note(std::string message, bool warning);

    LiveControls& controls_;
    double focusForKeys_ = 2.0;
    std::string message_;
    bool messageWarning_ = false;
    Clock::time_point messageUntil_{};
};

} // namespace defocus
