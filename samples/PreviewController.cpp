// SPDX-License-Identifier: LGPL-2.1-or-later
// The preview's controls: what each key and click does to the lens, the view and the focus,
// and the HUD's text (samples/PreviewController.hpp).
#include "samples/PreviewController.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace defocus {
namespace {

constexpr auto kMessageTime = std::chrono::seconds(4);

int viewNumber(Settings::View view)
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

std::string rangeText(const Lens& lens)
{
    if (lens.cocModel == Lens::Model::ThinLens)
        return "thin-lens";
    return fmt::format("focal range {:.2f}-{:.2f} m", lens.nearM, lens.farM);
}

/// The aperture in a few words: "6 blades", "circle", "9 blades 15 deg", "circle, ratio 2".
std::string apertureText(const Lens& lens)
{
    std::string text = lens.blades == 0 ? "circle" : fmt::format("{} blades", lens.blades);
    if (lens.blades != 0 && lens.bladeRotationDeg != 0.0)
        text += fmt::format(" {:g} deg", lens.bladeRotationDeg);
    if (lens.apertureRatio != 1.0)
        text += fmt::format(", ratio {:g}", lens.apertureRatio);
    return text;
}

/// The blade count after `blades`: 6, 7 ... 16, then the circle, then 3, 4, 5 and 6 again.
int nextBlades(int blades)
{
    if (blades == 0)
        return 3;
    return blades >= 16 ? 0 : blades + 1;
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

} // namespace

KeyOutcome applyKey(LiveControls& controls, int key, double focusM)
{
    KeyOutcome outcome;
    outcome.handled = true;
    Lens& lens = controls.lens;
    bool lensChanged = false;
    bool apertureChanged = false; // always valid: no check, the message names it
    switch (key) {
    case '1': case '2': case '3': case '4': case '5': case '6': case '7':
        controls.view = kViews[key - '1'];
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
        lens.cocModel = Lens::Model::FocalRange;
        controls.nearRatio = key == 'j' ? controls.nearRatio / 1.25 : controls.nearRatio * 1.25;
        controls.farRatio = key == 'j' ? controls.farRatio * 1.25 : controls.farRatio / 1.25;
        lensChanged = true;
        break;
    case 'b':
        lens.blades = nextBlades(lens.blades);
        apertureChanged = true;
        break;
    case 'r':
        lens.bladeRotationDeg = std::remainder(lens.bladeRotationDeg + 15.0, 360.0);
        apertureChanged = true;
        break;
    case 'o':
        lens.apertureRatio = lens.apertureRatio == 1.0 ? 2.0 : 1.0;
        apertureChanged = true;
        break;
    case 'm':
        lens.cocModel = lens.cocModel == Lens::Model::ThinLens ? Lens::Model::FocalRange : Lens::Model::ThinLens;
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
    if (apertureChanged)
        outcome.message = "aperture: " + apertureText(lens);
    if (lensChanged) {
        // Judge the new values on the lens they will be used with, and keep the clamped ones.
        const Lens used = lensFor(controls, focusM, &outcome.issues);
        lens.fNumber = used.fNumber;
        lens.maxCocPx = used.maxCocPx;
        if (used.cocModel == Lens::Model::FocalRange && std::isfinite(used.focusM)) {
            controls.nearRatio = used.nearM / used.focusM;
            controls.farRatio = used.farM / used.focusM;
        }
        outcome.message = fmt::format("f/{}, max CoC {:.1f} px, {}", fNumberText(used.fNumber), used.maxCocPx,
                                      rangeText(used));
    }
    ++controls.revision;
    return outcome;
}

Lens lensFor(const LiveControls& controls, double focusM, std::vector<std::string>* issues)
{
    Settings settings;
    Lens& lens = settings.lens;
    lens = controls.lens;
    lens.focusM = focusM;
    if (std::isfinite(focusM)) {
        lens.nearM = focusM * controls.nearRatio;
        lens.farM = focusM * controls.farRatio;
    } else {
        lens.farM = std::numeric_limits<double>::infinity();
    }
    auto found = check(settings, true);
    if (issues)
        issues->insert(issues->end(), found.begin(), found.end());
    return lens;
}

Hud hudFor(const HudStatus& status, const Plan* tileMap)
{
    Hud hud;
    hud.marks = {status.focusWindow.centre, status.focusWindow.size, status.autofocus};
    if (tileMap) {
        const int s = tileMap->tileSizePx;
        for (int y = 0; y < tileMap->tileMap.rows; ++y)
            for (int x = 0; x < tileMap->tileMap.cols; ++x)
                if (tileMap->tileMap.at<std::uint8_t>(y, x) != 0)
                    hud.outlines.emplace_back(x * s, y * s, s, s);
    }

    const Lens& lens = status.lens;
    std::string focus = fmt::format("focus {:.2f} m [{}{}]", status.focusM, status.autofocus ? "auto" : "manual",
                                    status.tapped ? ", tapped" : "");
    if (std::abs(status.targetM - status.focusM) > 0.005 * status.focusM)
        focus += fmt::format(" -> {:.2f} m", status.targetM);
    std::string state = status.paused ? "  PAUSED" : status.ended ? "  end of clip (held)" : "";
    std::string gpu;
    for (const auto& pass : status.gpu)
        gpu += fmt::format("  {} {:.1f}", shortPassName(pass.name), pass.ms);
    const Timings& t = status.timings;
    hud.lines = {
        fmt::format("{}   f/{}  {:.0f} mm  max CoC {:.1f} px  {}  {}", focus, fNumberText(lens.fNumber),
                    lens.focalLengthMm, lens.maxCocPx, rangeText(lens), apertureText(lens)),
        fmt::format("view {} {}   {:.1f} fps   latency {:.0f} ms   dropped {}   frame {}{}{}", viewNumber(status.view),
                    viewName(status.view), status.fps, status.latencyMs, status.dropped, status.frameIndex,
                    status.live ? " (live)" : "", state),
        fmt::format("ms: total {:.1f}  prep {:.1f}  analysis {:.1f}  upload {:.1f}  render {:.1f}  readback {:.1f}",
                    t.totalMs, t.depthPrepMs, t.analysisMs, t.uploadMs, t.renderMs, t.readbackMs),
        "gpu ms/pass:" + (gpu.empty() ? std::string("  n/a") : gpu),
    };
    hud.note = status.message.empty() ? std::string("keys: 1-7 view  +/- f-number  [ ] max CoC  j/l range  b/r/o aperture  "
                                                    "f autofocus  t tiles  spc pause  s shot  q quit")
                                      : status.message;
    hud.warning = status.warning;
    return hud;
}

void PreviewController::serve(DisplaySink& window)
{
    for (const WindowEvent& event : window.takeEvents())
        handle(event, &window);
}

void PreviewController::handle(const WindowEvent& event, DisplaySink* window)
{
    switch (event.kind) {
    case WindowEvent::Kind::Closed:
        controls_.quit = true;
        return;
    case WindowEvent::Kind::LeftClick:
        controls_.tap = event.point;
        ++controls_.revision;
        note(fmt::format("tap to focus at ({}, {})", event.pixel.x, event.pixel.y), false);
        return;
    case WindowEvent::Kind::RightClick:
        controls_.recentre = true;
        ++controls_.revision;
        note("focus: centre window", false);
        return;
    case WindowEvent::Kind::Key:
        break;
    }
    if (event.key == 's') {
        if (const auto shot = window ? window->saveScreenshot() : std::nullopt) {
            if (shot->written)
                note(fmt::format("screenshot: {}", shot->file.string()), false);
            else
                note(fmt::format("screenshot: cannot write '{}'", shot->file.string()), true);
        }
        return;
    }
    const KeyOutcome outcome = applyKey(controls_, event.key, focusForKeys_);
    if (!outcome.handled) {
        spdlog::debug("key {} does nothing; keys: {}", event.key, kKeyHelp);
        return;
    }
    for (const auto& issue : outcome.issues)
        note(fmt::format("clamped: {}", issue), true);
    if (outcome.issues.empty() && !outcome.message.empty())
        note(outcome.message, false);
}

Hud PreviewController::hud(const HudStatus& status, const Plan* tileMap) const
{
    if (!status.message.empty() || Clock::now() >= messageUntil_)
        return hudFor(status, tileMap);
    HudStatus noted = status;
    noted.message = message_;
    noted.warning = messageWarning_;
    return hudFor(noted, tileMap);
}

void PreviewController::note(std::string message, bool warning)
{
    if (warning)
        spdlog::warn("{}", message);
    else
        spdlog::info("{}", message);
    message_ = std::move(message);
    messageWarning_ = warning;
    messageUntil_ = Clock::now() + kMessageTime;
}

} // namespace defocus
