// SPDX-License-Identifier: LGPL-2.1-or-later
// The preview window: key and mouse controls, HUD composition and screenshots, on highgui.
#include "sinks/DisplaySink.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <system_error>

#include <dlfcn.h>

#include <fmt/format.h>
#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "filter/Log.hpp"

namespace defocus {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kMinHudWidth = 560;
constexpr int kLineHeight = 18;
constexpr double kFontScale = 0.42;
constexpr auto kMessageTime = std::chrono::seconds(4);

int viewNumber(View view)
{
    return static_cast<int>(view) + 1;
}

std::string fNumberText(double n)
{
    return n < 10.0 ? fmt::format("{:.1f}", n) : fmt::format("{:.0f}", n);
}

/// One third of a stop on the standard scale: N = 2^(k/6) (a stop multiplies N by sqrt 2).
double thirdStop(double n, int direction)
{
    const double k = std::round(6.0 * std::log2(n));
    return std::exp2((k + direction) / 6.0);
}

std::string rangeText(const LensSettings& lens)
{
    if (lens.model == CocModel::ThinLens)
        return "thin-lens";
    return fmt::format("focal range {:.2f}-{:.2f} m", lens.nearLimitM, lens.farLimitM);
}

/// Short GPU pass names so that one line holds them all at 560 px.
std::string_view shortPassName(std::string_view name)
{
    if (name == "horizontal")
        return "h";
    if (name == "diagonal-a")
        return "a";
    if (name == "diagonal-b")
        return "b";
    if (name == "composite")
        return "comp";
    if (name == "near-field")
        return "near";
    return name;
}

void drawFocusMarks(cv::Mat& picture, const FocusWindow& window, bool active)
{
    const double w = std::max(window.size.width * picture.cols, 3.0);
    const double h = std::max(window.size.height * picture.rows, 3.0);
    const cv::Point2d c(window.centre.x * picture.cols, window.centre.y * picture.rows);
    const int x0 = static_cast<int>(std::lround(c.x - w / 2)), x1 = static_cast<int>(std::lround(c.x + w / 2));
    const int y0 = static_cast<int>(std::lround(c.y - h / 2)), y1 = static_cast<int>(std::lround(c.y + h / 2));
    const int arm = std::max(3, static_cast<int>(std::min(w, h) / 4));
    const cv::Scalar colour = active ? cv::Scalar(90, 230, 90) : cv::Scalar(170, 170, 170);
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

void drawTileMap(cv::Mat& picture, const SceneAnalysis& analysis)
{
    const int s = SceneAnalysis::kTileSize;
    const cv::Rect bounds(0, 0, picture.cols, picture.rows);
    for (int y = 0; y < analysis.tiles.height; ++y)
        for (int x = 0; x < analysis.tiles.width; ++x)
            if (analysis.tileNeedsBlur(x, y))
                cv::rectangle(picture, cv::Rect(x * s, y * s, s, s) & bounds, cv::Scalar(0, 200, 255), 1, cv::LINE_8);
}

} // namespace

KeyOutcome applyKey(LiveControls& controls, int key, double focusM)
{
    KeyOutcome outcome;
    outcome.handled = true;
    LensSettings& lens = controls.lens;
    bool lensChanged = false;
    switch (key) {
    case '1': case '2': case '3': case '4': case '5': case '6': case '7':
        controls.view = kAllViews[key - '1'];
        outcome.message = fmt::format("view {} {}", key - '0', viewName(controls.view));
        break;
    case '+': case '=':
    case '-': case '_':
        lens.fNumber = thirdStop(lens.fNumber, key == '+' || key == '=' ? 1 : -1);
        lensChanged = true;
        break;
    case '[':
        lens.maxCocPx -= lens.maxCocPx <= 4.0 ? 0.5 : 2.0;
        lensChanged = true;
        break;
    case ']':
        lens.maxCocPx += lens.maxCocPx < 4.0 ? 0.5 : 2.0;
        lensChanged = true;
        break;
    case 'j': // wider focal range: less blur (seed 003's keys)
    case 'l': // narrower: more blur
        lens.model = CocModel::FocalRange;
        controls.nearRatio = key == 'j' ? controls.nearRatio / 1.25 : controls.nearRatio * 1.25;
        controls.farRatio = key == 'j' ? controls.farRatio * 1.25 : controls.farRatio / 1.25;
        lensChanged = true;
        break;
    case 'm':
        lens.model = lens.model == CocModel::ThinLens ? CocModel::FocalRange : CocModel::ThinLens;
        lensChanged = true;
        break;
    case 'f':
        controls.autofocus = !controls.autofocus;
        outcome.message = controls.autofocus ? "autofocus on" : "autofocus off (click to focus)";
        break;
    case 'c':
        controls.recentre = true;
        outcome.message = "focus: centre window";
        break;
    case 't':
        controls.tileMap = !controls.tileMap;
        outcome.message = controls.tileMap ? "tile map on (outlined tiles are blurred)" : "tile map off";
        break;
    case ' ':
        controls.paused = !controls.paused;
        outcome.message = controls.paused ? "paused" : "playing";
        break;
    case 'q': case 27:
        controls.quit = true;
        outcome.message = "quit";
        break;
    default:
        outcome.handled = false;
        return outcome;
    }
    if (lensChanged) {
        // Judge the new values on the lens they will be used with, and keep the clamped ones.
        const LensSettings used = lensFor(controls, focusM, &outcome.issues);
        lens.fNumber = used.fNumber;
        lens.maxCocPx = used.maxCocPx;
        if (used.model == CocModel::FocalRange && std::isfinite(used.focusM)) {
            controls.nearRatio = used.nearLimitM / used.focusM;
            controls.farRatio = used.farLimitM / used.focusM;
        }
        outcome.message = fmt::format("f/{}, max CoC {:.1f} px, {}", fNumberText(used.fNumber), used.maxCocPx,
                                      rangeText(used));
    }
    ++controls.revision;
    return outcome;
}

LensSettings lensFor(const LiveControls& controls, double focusM, std::vector<SettingIssue>* issues)
{
    LensSettings lens = controls.lens;
    lens.focusM = focusM;
    if (std::isfinite(focusM)) {
        lens.nearLimitM = focusM * controls.nearRatio;
        lens.farLimitM = focusM * controls.farRatio;
    } else {
        lens.farLimitM = std::numeric_limits<double>::infinity();
    }
    auto found = validate(lens, true);
    if (issues)
        issues->insert(issues->end(), found.begin(), found.end());
    return lens;
}

cv::Mat composeHud(const cv::Mat& frame, const HudStatus& status, const SceneAnalysis* tileMap)
{
    CV_Assert(frame.type() == CV_8UC3 && !frame.empty());
    const int width = std::max(frame.cols, kMinHudWidth);
    cv::Mat out(frame.rows + kHudHeight, width, CV_8UC3, cv::Scalar(28, 28, 28));
    cv::Mat picture = out(cv::Rect(0, 0, frame.cols, frame.rows));
    frame.copyTo(picture);
    if (tileMap)
        drawTileMap(picture, *tileMap);
    drawFocusMarks(picture, status.focusWindow, status.autofocus);

    const LensSettings& lens = status.lens;
    std::string focus = fmt::format("focus {:.2f} m [{}{}]", status.focusM, status.autofocus ? "auto" : "manual",
                                    status.tapped ? ", tapped" : "");
    if (std::abs(status.targetM - status.focusM) > 0.005 * status.focusM)
        focus += fmt::format(" -> {:.2f} m", status.targetM);
    std::string state = status.paused ? "  PAUSED" : status.ended ? "  end of clip (held)" : "";
    std::string gpu;
    for (const auto& pass : status.gpu)
        gpu += fmt::format("  {} {:.1f}", shortPassName(pass.name), pass.ms);
    const FrameTimings& t = status.timings;
    const std::string lines[] = {
        fmt::format("{}   f/{}  {:.0f} mm  max CoC {:.1f} px  {}", focus, fNumberText(lens.fNumber), lens.focalLengthMm,
                    lens.maxCocPx, rangeText(lens)),
        fmt::format("view {} {}   {:.1f} fps   latency {:.0f} ms   dropped {}   frame {}{}{}", viewNumber(status.view),
                    viewName(status.view), status.fps, status.latencyMs, status.dropped, status.frameIndex,
                    status.live ? " (live)" : "", state),
        fmt::format("ms: total {:.1f}  prep {:.1f}  analysis {:.1f}  upload {:.1f}  render {:.1f}  readback {:.1f}",
                    t.totalMs, t.depthPrepMs, t.analysisMs, t.uploadMs, t.renderMs, t.readbackMs),
        "gpu ms/pass:" + (gpu.empty() ? std::string("  n/a") : gpu),
        status.message.empty() ? std::string("keys: 1-7 view  +/- f-number  [ ] max CoC  j/l range  f autofocus  "
                                             "t tiles  spc pause  s shot  q quit")
                               : status.message,
    };
    int y = frame.rows + kLineHeight;
    for (const auto& line : lines) {
        const bool last = &line == &lines[std::size(lines) - 1];
        const cv::Scalar ink = last && status.warning ? cv::Scalar(60, 160, 255)
                               : last                 ? cv::Scalar(190, 190, 190)
                                                      : cv::Scalar(245, 245, 245);
        cv::putText(out, line, {8, y}, cv::FONT_HERSHEY_SIMPLEX, kFontScale, ink, 1, cv::LINE_AA);
        y += kLineHeight;
    }
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

DisplaySink::DisplaySink(LiveControls& controls, DisplayOptions options)
    : controls_(controls), options_(std::move(options))
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

void DisplaySink::setStatus(const HudStatus& status, const SceneAnalysis* tileMap)
{
    status_ = status;
    tileMap_ = tileMap;
}

void DisplaySink::write(const cv::Mat& image)
{
    if (!open_)
        throw SinkError(fmt::format("DisplaySink: window '{}' is closed", options_.title));
    if (image.type() != CV_8UC3 || image.empty())
        throw SinkError(fmt::format("DisplaySink: expected a non-empty 8-bit BGR frame, got type {} {}x{}",
                                    image.type(), image.cols, image.rows));
    HudStatus status = status_;
    if (status.message.empty() && Clock::now() < messageUntil_) {
        status.message = message_;
        status.warning = messageWarning_;
    }
    frameSize_ = image.size();
    shown_ = composeHud(image, status, tileMap_);
    cv::imshow(options_.title, shown_);
    ++written_;
    poll(1);
}

void DisplaySink::poll(int waitMs)
{
    if (!open_)
        return;
    const int key = cv::waitKey(std::max(1, waitMs));
    if (key != -1)
        handleKey(key);
    if (cv::getWindowProperty(options_.title, cv::WND_PROP_VISIBLE) < 1.0) {
        open_ = false;
        controls_.quit = true;
        logger().info("window closed");
    }
}

void DisplaySink::handleKey(int key)
{
    if (key == 's') {
        saveScreenshot();
        return;
    }
    const KeyOutcome outcome = applyKey(controls_, key, focusForKeys_);
    if (!outcome.handled) {
        logger().debug("key {} does nothing; keys: {}", key, kKeyHelp);
        return;
    }
    for (const auto& issue : outcome.issues)
        note(fmt::format("clamped: {}", issue.message), true);
    if (outcome.issues.empty() && !outcome.message.empty())
        note(outcome.message, false);
}

void DisplaySink::onMouse(int event, int x, int y, int, void* self)
{
    auto& sink = *static_cast<DisplaySink*>(self);
    if (x < 0 || y < 0 || x >= sink.frameSize_.width || y >= sink.frameSize_.height)
        return; // the HUD band, or before the first frame
    if (event == cv::EVENT_LBUTTONDOWN) {
        sink.controls_.tap = cv::Point2d((x + 0.5) / sink.frameSize_.width, (y + 0.5) / sink.frameSize_.height);
        ++sink.controls_.revision;
        sink.note(fmt::format("tap to focus at ({}, {})", x, y), false);
    } else if (event == cv::EVENT_RBUTTONDOWN) {
        sink.controls_.recentre = true;
        ++sink.controls_.revision;
        sink.note("focus: centre window", false);
    }
}

void DisplaySink::note(std::string message, bool warning)
{
    if (warning)
        logger().warn("{}", message);
    else
        logger().info("{}", message);
    message_ = std::move(message);
    messageWarning_ = warning;
    messageUntil_ = Clock::now() + kMessageTime;
}

void DisplaySink::saveScreenshot()
{
    if (shown_.empty())
        return;
    std::error_code ec;
    std::filesystem::create_directories(options_.screenshotDir, ec);
    std::filesystem::path file;
    do
        file = options_.screenshotDir / fmt::format("defocus-preview-{:04}.png", ++screenshots_);
    while (std::filesystem::exists(file, ec));
    bool ok = false;
    try {
        ok = cv::imwrite(file.string(), shown_, {cv::IMWRITE_PNG_COMPRESSION, 9});
    } catch (const cv::Exception&) {
        ok = false;
    }
    if (ok)
        note(fmt::format("screenshot: {}", file.string()), false);
    else
        note(fmt::format("screenshot: cannot write '{}'", file.string()), true);
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
