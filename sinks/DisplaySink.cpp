// SPDX-License-Identifier: LGPL-2.1-or-later
// The preview window on highgui: the frame with its HUD band, the keys and clicks it receives,
// screenshots.
#include "sinks/DisplaySink.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <system_error>
#include <utility>

#include <dlfcn.h>

#include <fmt/format.h>
#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "filter/Log.hpp"

namespace defocus {
namespace {

constexpr int kMinHudWidth = 560;
constexpr int kLineHeight = 18;
constexpr double kFontScale = 0.42;

void drawMarks(cv::Mat& picture, const HudMarks& marks)
{
    const double w = std::max(marks.size.width * picture.cols, 3.0);
    const double h = std::max(marks.size.height * picture.rows, 3.0);
    const cv::Point2d c(marks.centre.x * picture.cols, marks.centre.y * picture.rows);
    const int x0 = static_cast<int>(std::lround(c.x - w / 2)), x1 = static_cast<int>(std::lround(c.x + w / 2));
    const int y0 = static_cast<int>(std::lround(c.y - h / 2)), y1 = static_cast<int>(std::lround(c.y + h / 2));
    const int arm = std::max(3, static_cast<int>(std::min(w, h) / 4));
    const cv::Scalar colour = marks.active ? cv::Scalar(90, 230, 90) : cv::Scalar(170, 170, 170);
    for (const auto& [thickness, ink] : {std::pair{3, cv::Scalar(0, 0, 0)}, std::pair{1, colour}}) {
        for (const int x : {x0, x1}) {
            const int dx = x == x0 ? arm : -arm;
            for (const int y : {y0, y1}) {
                const int dy = y == y0 ? arm : -arm;
                cv::line(picture, {x, y}, {x + dx, y}, ink, thickness, cv::LINE_8);
                cv::line(picture, {x, y}, {x, y + dy}, ink, thickness, cv::LINE_8);
            }
        }
    }
}

} // namespace

cv::Mat composeHud(const cv::Mat& frame, const Hud& hud)
{
    CV_Assert(frame.type() == CV_8UC3 && !frame.empty());
    const int width = std::max(frame.cols, kMinHudWidth);
    cv::Mat out(frame.rows + kHudHeight, width, CV_8UC3, cv::Scalar(28, 28, 28));
    cv::Mat picture = out(cv::Rect(0, 0, frame.cols, frame.rows));
    frame.copyTo(picture);
    const cv::Rect bounds(0, 0, picture.cols, picture.rows);
    for (const cv::Rect& outline : hud.outlines)
        cv::rectangle(picture, outline & bounds, cv::Scalar(0, 200, 255), 1, cv::LINE_8);
    drawMarks(picture, hud.marks);

    int y = frame.rows + kLineHeight;
    const auto draw = [&](const std::string& line, const cv::Scalar& ink) {
        cv::putText(out, line, {8, y}, cv::FONT_HERSHEY_SIMPLEX, kFontScale, ink, 1, cv::LINE_AA);
        y += kLineHeight;
    };
    for (const auto& line : hud.lines)
        draw(line, cv::Scalar(245, 245, 245));
    draw(hud.note, hud.warning ? cv::Scalar(60, 160, 255) : cv::Scalar(190, 190, 190));
    return out;
}

namespace {

/// Whether an X server answers at DISPLAY, asked as Qt's xcb platform asks (xcb_connect, from the
/// libxcb that Qt loads; looked up at run time, so the build needs no X headers). True where
/// libxcb is missing: the window's own error says why then.
bool xServerAnswers()
{
    void* xcb = ::dlopen("libxcb.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!xcb)
        return true;
    using Connect = void* (*)(const char*, int*);
    using HasError = int (*)(void*);
    using Disconnect = void (*)(void*);
    const auto connect = reinterpret_cast<Connect>(::dlsym(xcb, "xcb_connect"));
    const auto hasError = reinterpret_cast<HasError>(::dlsym(xcb, "xcb_connection_has_error"));
    const auto disconnect = reinterpret_cast<Disconnect>(::dlsym(xcb, "xcb_disconnect"));
    bool answers = true;
    if (connect && hasError && disconnect) {
        void* connection = connect(nullptr, nullptr); // never null: a connection in an error state
        answers = hasError(connection) == 0;
        disconnect(connection);
    }
    ::dlclose(xcb);
    return answers;
}

} // namespace

DisplaySink::DisplaySink(DisplayOptions options) : options_(std::move(options))
{
    // highgui's Qt backend aborts the whole process when it cannot reach a display, so look first.
    const auto set = [](const char* name) {
        const char* value = std::getenv(name);
        return value && *value;
    };
    if (!set("DISPLAY") && !set("WAYLAND_DISPLAY") && !set("QT_QPA_PLATFORM"))
        throw SinkError("DisplaySink: no display to open a window on (DISPLAY is not set); run under X11, "
                        "Wayland or Xvfb, or use --no-window");
    if (set("DISPLAY") && !set("QT_QPA_PLATFORM") && !xServerAnswers())
        throw SinkError(fmt::format("DisplaySink: no X server answers at DISPLAY={} (a stale DISPLAY?); start "
                                    "one or Xvfb there, or use --no-window",
                                    std::getenv("DISPLAY")));
    try {
        cv::namedWindow(options_.title, cv::WINDOW_AUTOSIZE | cv::WINDOW_KEEPRATIO | cv::WINDOW_GUI_NORMAL);
        cv::setMouseCallback(options_.title, &DisplaySink::onMouse, this);
    } catch (const cv::Exception& e) {
        throw SinkError(fmt::format("DisplaySink: cannot open window '{}': {}", options_.title, e.what()));
    }
    open_ = true;
}

DisplaySink::~DisplaySink()
{
    finish();
}

void DisplaySink::write(const cv::Mat& image)
{
    if (!open_)
        throw SinkError(fmt::format("DisplaySink: window '{}' is closed", options_.title));
    if (image.type() != CV_8UC3 || image.empty())
        throw SinkError(fmt::format("DisplaySink: expected a non-empty 8-bit BGR frame, got type {} {}x{}",
                                    image.type(), image.cols, image.rows));
    frameSize_ = image.size();
    shown_ = composeHud(image, hud_);
    cv::imshow(options_.title, shown_);
    ++written_;
    poll(1);
}

void DisplaySink::poll(int waitMs)
{
    if (!open_)
        return;
    const int key = cv::waitKey(std::max(1, waitMs));
    if (key != -1) {
        WindowEvent event;
        event.key = key;
        events_.push_back(event);
    }
    if (cv::getWindowProperty(options_.title, cv::WND_PROP_VISIBLE) < 1.0) {
        open_ = false;
        WindowEvent event;
        event.kind = WindowEvent::Kind::Closed;
        events_.push_back(event);
        logger().info("window closed");
    }
}

std::vector<WindowEvent> DisplaySink::takeEvents()
{
    return std::exchange(events_, {});
}

void DisplaySink::onMouse(int event, int x, int y, int, void* self)
{
    auto& sink = *static_cast<DisplaySink*>(self);
    if (x < 0 || y < 0 || x >= sink.frameSize_.width || y >= sink.frameSize_.height)
        return; // the HUD band, or before the first frame
    if (event != cv::EVENT_LBUTTONDOWN && event != cv::EVENT_RBUTTONDOWN)
        return;
    WindowEvent click;
    click.kind = event == cv::EVENT_LBUTTONDOWN ? WindowEvent::Kind::LeftClick : WindowEvent::Kind::RightClick;
    click.pixel = {x, y};
    click.point = cv::Point2d((x + 0.5) / sink.frameSize_.width, (y + 0.5) / sink.frameSize_.height);
    sink.events_.push_back(click);
}

std::optional<Screenshot> DisplaySink::saveScreenshot()
{
    if (shown_.empty())
        return std::nullopt;
    std::error_code ec;
    std::filesystem::create_directories(options_.screenshotDir, ec);
    Screenshot shot;
    do
        shot.file = options_.screenshotDir / fmt::format("defocus-preview-{:04}.png", ++screenshots_);
    while (std::filesystem::exists(shot.file, ec));
    try {
        shot.written = cv::imwrite(shot.file.string(), shown_, {cv::IMWRITE_PNG_COMPRESSION, 9});
    } catch (const cv::Exception&) {
        shot.written = false;
    }
    return shot;
}

void DisplaySink::finish()
{
    if (!open_)
        return;
    open_ = false;
    try {
        cv::destroyWindow(options_.title);
        cv::waitKey(1);
    } catch (const cv::Exception&) {
        // the window may be gone already; nothing to finalise
    }
}

std::string DisplaySink::describe() const
{
    return fmt::format("window '{}' ({} frames shown)", options_.title, written_);
}

} // namespace defocus
