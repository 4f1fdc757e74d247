// SPDX-License-Identifier: LGPL-2.1-or-later
// A window on the screen (OpenCV highgui): each frame with a HUD band below it, drawn from what
// the program hands it (lines of text, focus marks, tile outlines), and the keys, clicks and the
// closing of the window it receives, queued for the program. What a key does is the program's
// (defocus-preview: samples/PreviewController.hpp; keys in docs/preview.md).
//   defocus-preview data/tum_fr1_rpy
//   defocus-preview /dev/video0 --depth depth.png
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "sinks/FrameSink.hpp"

namespace defocus {

/// Corner marks on the frame around a region, e.g. where the autofocus measures.
struct HudMarks {
    cv::Point2d centre{0.5, 0.5}; ///< normalised [0, 1] image coordinates
    cv::Size2d size{0.1, 0.1};    ///< fraction of each axis; drawn at least 3 px
    bool active = true;           ///< green when active, grey when not
};

/// What the window draws besides the frame.
struct Hud {
    /// The band's lines, top to bottom, in white; four fit above `note`.
    std::vector<std::string> lines;
    /// The band's last line, in grey; in orange when `warning`.
    std::string note;
    bool warning = false;
    HudMarks marks;
    /// Rectangles outlined in orange on the frame (pixels; clipped to it), drawn under the marks.
    std::vector<cv::Rect> outlines;
};

/// Height of the HUD band below the frame, pixels: five lines of 18 px.
inline constexpr int kHudHeight = 98;

/// The picture the window shows: `frame` (CV_8UC3) with the outlines and the marks of `hud`,
/// then the HUD band below it. The result is at least 560 px wide (narrow frames are padded on
/// the right) so the HUD fits.
cv::Mat composeHud(const cv::Mat& frame, const Hud& hud);

/// One thing the window received.
struct WindowEvent {
    enum class Kind {
        Key,        ///< a key, `key`
        LeftClick,  ///< a left click on the frame (not on the HUD band), at `pixel` / `point`
        RightClick, ///< a right click on the frame
        Closed,     ///< the window was closed; nothing more is shown
    };
    Kind kind = Kind::Key;
    int key = -1;      ///< as cv::waitKey() returns it (ASCII; 27 = Esc)
    cv::Point pixel;   ///< the clicked pixel of the frame
    cv::Point2d point; ///< the clicked pixel's centre, normalised [0, 1] image coordinates
};

struct DisplayOptions {
    /// Window title; also how tests find the window.
    std::string title = "defocus-preview";
    /// Where saveScreenshot() writes defocus-preview-NNNN.png.
    std::filesystem::path screenshotDir = ".";
};

/// A screenshot: the file, and whether it was written.
struct Screenshot {
    std::filesystem::path file;
    bool written = false;
};

/// The window. Needs a display: DISPLAY (X11, Xvfb) or WAYLAND_DISPLAY, or QT_QPA_PLATFORM for
/// Qt builds of highgui; without one, or with a DISPLAY where no X server answers, the
/// constructor throws SinkError (highgui's Qt backend would otherwise abort the process).
/// highgui is single-threaded: one thread shows, polls and takes the events.
class DisplaySink final : public FrameSink {
public:
    explicit DisplaySink(DisplayOptions options = {});
    ~DisplaySink() override;
    DisplaySink(const DisplaySink&) = delete;
    DisplaySink& operator=(const DisplaySink&) = delete;

    SinkEncoding encoding() const override { return SinkEncoding::Srgb8; }
    /// The HUD for the next write().
    void setHud(Hud hud) { hud_ = std::move(hud); }
    /// Shows `image` with the HUD, then gathers pending window events (1 ms).
    void write(const cv::Mat& image) override;
    /// Gathers keys, clicks and a closed window for up to `waitMs` (at least 1 ms).
    void poll(int waitMs);
    /// The events gathered since the last call, oldest first.
    std::vector<WindowEvent> takeEvents();
    /// Writes the last picture shown (frame + HUD, as on screen) to the next free
    /// defocus-preview-NNNN.png of the screenshot folder; nullopt before the first frame.
    std::optional<Screenshot> saveScreenshot();
    /// Closes the window. Idempotent.
    void finish() override;
    std::size_t framesWritten() const override { return written_; }
    std::string describe() const override;

    /// The last picture shown (frame + HUD), as on screen.
    const cv::Mat& shown() const { return shown_; }

private:
    static void onMouse(int event, int x, int y, int flags, void* self);

    DisplayOptions options_;
    Hud hud_;
    cv::Size frameSize_;
    cv::Mat shown_;
    std::vector<WindowEvent> events_;
    std::size_t written_ = 0;
    int screenshots_ = 0;
    bool open_ = false;
};

} // namespace defocus
