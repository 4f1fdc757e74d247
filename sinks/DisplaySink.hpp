// SPDX-License-Identifier: LGPL-2.1-or-later
// A window on the screen (OpenCV highgui): each frame with a HUD band below it, and the live
// controls its keys and mouse drive. The preview loop reads the controls every frame.
//   defocus-preview data/tum_fr1_rpy                 (keys: kKeyHelp below, docs/preview.md)
//   defocus-preview /dev/video0 --depth depth.png
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "filter/Autofocus.hpp"
#include "filter/Pipeline.hpp"
#include "filter/SceneAnalysis.hpp"
#include "filter/Settings.hpp"
#include "sinks/FrameSink.hpp"

namespace defocus {

/// What the keys and the mouse change; the preview loop reads it before every frame. Lives on
/// the thread that runs the window (highgui is single-threaded), so it needs no lock.
struct LiveControls {
    /// f-number, max CoC, model, focal length and sensor; focusM is not used (the focus comes
    /// from Autofocus) and near/far come from the ratios below.
    LensSettings lens;
    /// Focal-range model: near limit = focus * nearRatio, (0, 1). Default 0.5 (1 m at 2 m).
    double nearRatio = 0.5;
    /// Focal-range model: far limit = focus * farRatio, (1, +inf). Default 3 (6 m at 2 m).
    double farRatio = 3.0;
    View view = View::Composite;
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
    "f autofocus | c centre | t tiles | space pause | s screenshot | q quit | click: focus";

/// What applying a key did, for the log and the HUD.
struct KeyOutcome {
    bool handled = false;
    std::string message;          ///< e.g. "f/2.8"; empty for keys with nothing to say
    std::vector<SettingIssue> issues; ///< clamps, e.g. "--f-number must be between 0.7 and 64, not 71.8"
};

/// Applies one key as cv::waitKey() returns it (ASCII; 27 = Esc). The f-number moves by 1/3
/// stop (x 2^(1/6)) on the standard scale, max CoC by 2 px (0.5 px below 4 px), the focal range
/// by x 1.25 each side (j wider, l narrower, switching to the focal-range model). Impossible
/// values are clamped by validate(lens, true), judged at `focusM`, with the issue returned. 's'
/// is handled by DisplaySink (it owns the picture), not here.
KeyOutcome applyKey(LiveControls& controls, int key, double focusM);

/// The lens for one frame: the controls with `focusM` and the focal-range limits from the
/// ratios, clamped by validate(lens, true); what was clamped goes to `issues` when given.
LensSettings lensFor(const LiveControls& controls, double focusM, std::vector<SettingIssue>* issues = nullptr);

/// What the HUD shows besides the controls.
struct HudStatus {
    double focusM = 2.0;       ///< focus in use, metres
    double targetM = 2.0;      ///< where autofocus is heading, metres
    bool autofocus = true;
    bool tapped = false;       ///< the focus region is a tapped point, not the centre
    FocusWindow focusWindow;   ///< drawn as corner marks on the frame
    LensSettings lens;         ///< as used for the frame (after clamping)
    View view = View::Composite;
    double fps = 0.0;          ///< new frames shown per second, recent average
    double latencyMs = 0.0;    ///< capture (or read) to display, recent average
    std::size_t dropped = 0;   ///< live frames replaced before processing
    std::size_t frameIndex = 0;
    bool paused = false;
    bool live = false;
    bool ended = false;        ///< a recorded source has no more frames; the last one is held
    FrameTimings timings;
    std::vector<PassTime> gpu; ///< last known GPU time per pass (timings.gpu arrives a frame late)
    std::string message;       ///< a transient line (the last key's effect or a warning)
    bool warning = false;      ///< `message` is a warning (drawn in orange)
};

/// Height of the HUD band below the frame, pixels.
inline constexpr int kHudHeight = 98;

/// The picture the window shows: `frame` (CV_8UC3) with the focus-region marks and, when
/// `tileMap` is given, the outlines of the tiles that need blur; then the HUD band below it.
/// The result is at least 560 px wide (narrow frames are padded on the right) so the HUD fits.
cv::Mat composeHud(const cv::Mat& frame, const HudStatus& status, const SceneAnalysis* tileMap = nullptr);

struct DisplayOptions {
    /// Window title; also how tests find the window.
    std::string title = "defocus-preview";
    /// Where 's' writes defocus-preview-NNNN.png.
    std::filesystem::path screenshotDir = ".";
};

/// The window. Needs a display: DISPLAY (X11, Xvfb) or WAYLAND_DISPLAY, or QT_QPA_PLATFORM for
/// Qt builds of highgui; without one, or with a DISPLAY where no X server answers, the
/// constructor throws SinkError (highgui's Qt backend would otherwise abort the process).
class DisplaySink final : public FrameSink {
public:
    DisplaySink(LiveControls& controls, DisplayOptions options = {});
    ~DisplaySink() override;
    DisplaySink(const DisplaySink&) = delete;
    DisplaySink& operator=(const DisplaySink&) = delete;

    SinkEncoding encoding() const override { return SinkEncoding::Srgb8; }
    /// The HUD for the next write(); `tileMap` (may be null) must live until then.
    void setStatus(const HudStatus& status, const SceneAnalysis* tileMap = nullptr);
    /// Shows `image` with the HUD, then handles pending window events (1 ms).
    void write(const cv::Mat& image) override;
    /// Handles keys, clicks and a closed window for up to `waitMs` (at least 1 ms).
    void poll(int waitMs);
    /// Closes the window. Idempotent.
    void finish() override;
    std::size_t framesWritten() const override { return written_; }
    std::string describe() const override;

    /// The last picture shown (frame + HUD), as on screen.
    const cv::Mat& shown() const { return shown_; }
    /// Current focus, for judging clamps of keys (set by the loop).
    void setFocusForKeys(double focusM) { focusForKeys_ = focusM; }

private:
    static void onMouse(int event, int x, int y, int flags, void* self);
    void handleKey(int key);
    void note(std::string message, bool warning);
    void saveScreenshot();

    LiveControls& controls_;
    DisplayOptions options_;
    HudStatus status_;
    const SceneAnalysis* tileMap_ = nullptr;
    cv::Size frameSize_;
    cv::Mat shown_;
    std::size_t written_ = 0;
    int screenshots_ = 0;
    bool open_ = false;
    double focusForKeys_ = 2.0;
    std::string message_;
    bool messageWarning_ = false;
    std::chrono::steady_clock::time_point messageUntil_{};
};

} // namespace defocus
