// SPDX-License-Identifier: LGPL-2.1-or-later
// The display sink in a real window: runs defocus-preview on the bundled TUM clip under Xvfb,
// reads the screen from Xvfb's framebuffer file (-fbdir, XWD format), and drives the window with
// xdotool: the processed frame and the HUD are on screen, keys switch views (checked through
// changed pixels), a click focuses there. Run by scripts/display-test.sh, which starts Xvfb and
// sets DISPLAY, DEFOCUS_PREVIEW (the program) and DEFOCUS_XVFB_SCREEN (the framebuffer file).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "filter/Autofocus.hpp"
#include "filter/DepthPrep.hpp"
#include "sinks/DisplaySink.hpp"
#include "sources/FrameSource.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

std::string env(const char* name)
{
    const char* value = std::getenv(name);
    return value ? value : "";
}

/// Reads an XWD file as Xvfb keeps it (-fbdir): a big-endian header, a colour map, then
/// ZPixmap pixels of `bits_per_pixel` in `byte_order`; returns BGR.
cv::Mat readXwd(const std::string& file)
{
    std::ifstream in(file, std::ios::binary);
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.size() < 100)
        return {};
    const auto field = [&](int i) {
        const unsigned char* p = bytes.data() + 4 * i;
        return static_cast<std::uint32_t>(p[0]) << 24 | static_cast<std::uint32_t>(p[1]) << 16 |
               static_cast<std::uint32_t>(p[2]) << 8 | p[3];
    };
    const std::uint32_t headerSize = field(0), format = field(2), width = field(4), height = field(5),
                        byteOrder = field(7), bitsPerPixel = field(11), bytesPerLine = field(12),
                        redMask = field(14), greenMask = field(15), blueMask = field(16), colours = field(19);
    if (format != 2 || (bitsPerPixel != 32 && bitsPerPixel != 24))
        return {};
    const std::size_t offset = headerSize + colours * 12u;
    if (bytes.size() < offset + static_cast<std::size_t>(bytesPerLine) * height)
        return {};
    const auto shiftOf = [](std::uint32_t mask) {
        int s = 0;
        while (mask && !(mask & 1u)) {
            mask >>= 1;
            ++s;
        }
        return s;
    };
    const int rs = shiftOf(redMask), gs = shiftOf(greenMask), bs = shiftOf(blueMask);
    const std::uint32_t bytesPerPixel = bitsPerPixel / 8;
    cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_8UC3);
    for (std::uint32_t y = 0; y < height; ++y) {
        const unsigned char* row = bytes.data() + offset + static_cast<std::size_t>(y) * bytesPerLine;
        auto* out = image.ptr<cv::Vec3b>(static_cast<int>(y));
        for (std::uint32_t x = 0; x < width; ++x) {
            const unsigned char* p = row + x * bytesPerPixel;
            std::uint32_t v = 0;
            for (std::uint32_t b = 0; b < bytesPerPixel; ++b)
                v |= static_cast<std::uint32_t>(p[byteOrder == 0 ? b : bytesPerPixel - 1 - b]) << (8 * b);
            out[x] = {static_cast<uchar>((v & blueMask) >> bs), static_cast<uchar>((v & greenMask) >> gs),
                      static_cast<uchar>((v & redMask) >> rs)};
        }
    }
    return image;
}

std::string run(const std::string& command)
{
    std::string output;
    if (FILE* pipe = ::popen(command.c_str(), "r")) {
        std::array<char, 256> buffer{};
        while (std::fgets(buffer.data(), buffer.size(), pipe))
            output += buffer.data();
        ::pclose(pipe);
    }
    return output;
}

void xdotool(const std::string& arguments)
{
    ASSERT_EQ(std::system(("xdotool " + arguments).c_str()), 0) << "xdotool " << arguments;
}

/// defocus-preview as a child process, its stdout and stderr going to `log`.
class Preview {
public:
    Preview(const std::vector<std::string>& arguments, const std::string& log) : log_(log)
    {
        pid_ = ::fork();
        if (pid_ == 0) {
            const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            ::dup2(fd, 1);
            ::dup2(fd, 2);
            std::vector<char*> argv;
            for (const auto& a : arguments)
                argv.push_back(const_cast<char*>(a.c_str()));
            argv.push_back(nullptr);
            ::execv(argv[0], argv.data());
            std::_Exit(127);
        }
    }
    ~Preview()
    {
        if (pid_ > 0 && !exited_) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
    }
    std::string log() const
    {
        std::ifstream in(log_);
        std::stringstream s;
        s << in.rdbuf();
        return s.str();
    }
    /// Waits until a line of the log (from line `from` on) matches `pattern` and `accept`
    /// (given the match's groups); returns the groups, [0] being the whole match.
    using Groups = std::vector<std::string>;
    std::optional<Groups> waitFor(const std::regex& pattern, std::chrono::milliseconds timeout, std::size_t from = 0,
                                  const std::function<bool(const Groups&)>& accept = {})
    {
        const auto deadline = Clock::now() + timeout;
        do {
            std::istringstream lines(log());
            std::string line;
            std::size_t n = 0;
            while (std::getline(lines, line)) {
                if (n++ < from)
                    continue;
                std::smatch match;
                if (!std::regex_search(line, match, pattern))
                    continue;
                Groups groups(match.begin(), match.end());
                if (!accept || accept(groups))
                    return groups;
            }
            if (exited())
                return std::nullopt;
            std::this_thread::sleep_for(50ms);
        } while (Clock::now() < deadline);
        return std::nullopt;
    }
    std::size_t lines() const
    {
        const std::string text = log();
        return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
    }
    bool exited()
    {
        if (exited_)
            return true;
        int status = 0;
        if (::waitpid(pid_, &status, WNOHANG) == pid_) {
            exited_ = true;
            status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        }
        return exited_;
    }
    std::optional<int> waitExit(std::chrono::milliseconds timeout)
    {
        const auto deadline = Clock::now() + timeout;
        while (!exited() && Clock::now() < deadline)
            std::this_thread::sleep_for(50ms);
        return exited_ ? std::optional<int>(status_) : std::nullopt;
    }

private:
    std::string log_;
    pid_t pid_ = -1;
    bool exited_ = false;
    int status_ = -1;
};

/// Share of pixels whose largest channel difference exceeds `threshold` levels.
double changedFraction(const cv::Mat& a, const cv::Mat& b, int threshold = 8)
{
    cv::Mat diff, largest;
    cv::absdiff(a, b, diff);
    cv::Mat channels[3];
    cv::split(diff, channels);
    largest = cv::max(cv::max(channels[0], channels[1]), channels[2]);
    return cv::countNonZero(largest > threshold) / static_cast<double>(largest.total());
}

class DisplayXvfb : public ::testing::Test {
protected:
    void SetUp() override
    {
        if (env("DISPLAY").empty() || env("DEFOCUS_PREVIEW").empty() || env("DEFOCUS_XVFB_SCREEN").empty())
            GTEST_SKIP() << "run through scripts/display-test.sh (ctest -L display): it starts Xvfb";
    }

    /// The window's picture once two reads 150 ms apart agree (the last paint is through).
    cv::Mat screen()
    {
        cv::Mat previous;
        const auto deadline = Clock::now() + 5s;
        for (;;) {
            std::this_thread::sleep_for(150ms);
            const cv::Mat full = readXwd(env("DEFOCUS_XVFB_SCREEN"));
            if (full.empty())
                continue;
            const cv::Mat window = full(window_ & cv::Rect(0, 0, full.cols, full.rows)).clone();
            if (!previous.empty() && cv::norm(window, previous, cv::NORM_INF) == 0)
                return window;
            if (Clock::now() > deadline)
                return window;
            previous = window;
        }
    }

    cv::Rect window_;
};

TEST_F(DisplayXvfb, PreviewShowsTheProcessedFrameAndReactsToKeysAndClicks)
{
    const auto scratch = test::scratchDir("display-xvfb");
    // The last frame of the clip: what the window holds at the end, and what view 1 must show.
    SourceOptions options;
    options.input = test::dataDir() / "tum_fr1_rpy";
    auto source = openSource(options);
    Frame last;
    while (auto frame = source->next())
        last = std::move(*frame);
    ASSERT_EQ(last.color.size(), cv::Size(640, 480));

    // Full size: the balanced preset blurs at half size, where view 1 (the blur's input) is the
    // half-size target shown 2x2 per texel; at full size it is the frame itself, as checked below.
    Preview preview({env("DEFOCUS_PREVIEW"), options.input.string(), "--trace", "--tau", "0.05", "--resolution", "full",
                     "--screenshot-dir", scratch.string()},
                    (scratch / "preview.log").string());
    const std::regex ended(R"(shown frame=9 new=0 view=composite .*ended=1)");
    ASSERT_TRUE(preview.waitFor(ended, 45s)) << preview.log();

    // The window: the frame with the HUD band below, at the top left of a screen with no
    // window manager.
    const std::string geometry = run("xdotool search --name '^defocus-preview$' getwindowgeometry --shell");
    std::smatch g;
    ASSERT_TRUE(std::regex_search(geometry, g, std::regex(R"(X=(\d+)\s+Y=(\d+)\s+WIDTH=(\d+)\s+HEIGHT=(\d+))")))
        << geometry;
    window_ = cv::Rect(std::stoi(g[1]), std::stoi(g[2]), std::stoi(g[3]), std::stoi(g[4]));
    ASSERT_EQ(window_.size(), cv::Size(640, 480 + kHudHeight)) << geometry;
    const cv::Rect frameArea(0, 0, 640, 480), hudArea(0, 480, 640, kHudHeight);
    // Keys go to the window under the pointer (no window manager gives focus): park it on the HUD.
    xdotool(fmt::format("mousemove {} {}", window_.x + 600, window_.y + 480 + kHudHeight / 2));

    // 1. The processed frame is on screen, not the raw input, and the HUD below it.
    const cv::Mat composite = screen();
    const double blurred = changedFraction(composite(frameArea), last.color);
    EXPECT_GT(blurred, 0.15) << "the composite should differ from the raw frame wherever it is out of focus";
    cv::Mat hud;
    cv::cvtColor(composite(hudArea), hud, cv::COLOR_BGR2GRAY);
    const double text = cv::countNonZero(hud > 150) / static_cast<double>(hud.total());
    EXPECT_GT(text, 0.02) << "no HUD text";
    EXPECT_LT(text, 0.4) << "the HUD band should be mostly dark background";
    EXPECT_LT(cv::mean(hud)[0], 80.0);

    // 2. 's' saves what the window shows, pixel for pixel.
    std::size_t from = preview.lines();
    xdotool("key s");
    const auto saved = preview.waitFor(std::regex(R"(screenshot: (\S+\.png))"), 10s, from);
    ASSERT_TRUE(saved) << preview.log();
    const cv::Mat screenshot = cv::imread((*saved)[1]);
    cv::imwrite((scratch / "composite.png").string(), composite);
    ASSERT_EQ(screenshot.size(), composite.size());
    EXPECT_LE(cv::norm(screenshot, composite, cv::NORM_INF), 2.0);

    // 3. Key 1: the input view is the raw frame again (but for the autofocus marks).
    const auto pressAndWait = [&](const char* key, const char* view) {
        const std::size_t before = preview.lines();
        xdotool(std::string("key ") + key);
        return preview.waitFor(std::regex(std::string("shown frame=9 new=0 view=") + view + " "), 20s, before)
            .has_value();
    };
    ASSERT_TRUE(pressAndWait("1", "input")) << preview.log();
    const cv::Mat input = screen();
    EXPECT_LT(changedFraction(input(frameArea), last.color), 0.02) << "view 1 should show the input frame";
    EXPECT_GT(changedFraction(input(frameArea), composite(frameArea)), 0.15);
    EXPECT_GT(changedFraction(input(hudArea), composite(hudArea), 30), 0.0) << "the HUD should name the new view";

    // 4. Key 7: the CoC view, a colour map: most pixels change.
    ASSERT_TRUE(pressAndWait("7", "coc")) << preview.log();
    const cv::Mat coc = screen();
    EXPECT_GT(changedFraction(coc(frameArea), input(frameArea)), 0.5);

    // 5. Key 5: back to the composite, the same picture as before.
    ASSERT_TRUE(pressAndWait("5", "composite")) << preview.log();
    const cv::Mat again = screen();
    EXPECT_LT(changedFraction(again(frameArea), composite(frameArea)), 0.001);

    // 6. A click focuses where it lands: pick the spot whose depth is farthest (in dioptres)
    // from the autofocus's centre, and expect what Autofocus measures there.
    const double centreFocus = *measureFocus(last.depth, {});
    cv::Point tap;
    double tapDepth = centreFocus;
    for (int y = 40; y < 440; y += 20)
        for (int x = 40; x < 600; x += 20) {
            FocusWindow region{{(x + 0.5) / 640, (y + 0.5) / 480}, {0.02, 0.02 * 640 / 480}};
            const auto z = measureFocus(last.depth, region);
            if (z && std::abs(1.0 / *z - 1.0 / centreFocus) > std::abs(1.0 / tapDepth - 1.0 / centreFocus)) {
                tap = {x, y};
                tapDepth = *z;
            }
        }
    ASSERT_GT(std::abs(tapDepth - centreFocus), 0.2 * centreFocus);
    from = preview.lines();
    xdotool(fmt::format("mousemove {} {} click 1", window_.x + tap.x, window_.y + tap.y));
    const auto target = preview.waitFor(std::regex(R"(tap to focus: target ([0-9.]+) m)"), 10s, from);
    ASSERT_TRUE(target) << preview.log();
    EXPECT_NEAR(std::stod((*target)[1]), tapDepth, 0.01 * tapDepth) << "tapped at " << tap;
    // The spring glides there (tau 0.05 s, stepped with wall-clock time on a held frame).
    const auto settled = preview.waitFor(
        std::regex(R"(shown frame=9 new=0 view=composite focus=([0-9.]+) target=([0-9.]+))"), 30s, from,
        [&](const auto& groups) {
            const double focus = std::stod(groups[1]), goal = std::stod(groups[2]);
            return std::abs(goal - tapDepth) < 0.01 * tapDepth && std::abs(focus - goal) < 0.002 * goal;
        });
    EXPECT_TRUE(settled) << preview.log();
    const cv::Mat refocused = screen();
    EXPECT_GT(changedFraction(refocused(frameArea), composite(frameArea)), 0.05) << "the focus should have moved";

    // 7. q quits cleanly and reports the final focus.
    xdotool(fmt::format("mousemove {} {}", window_.x + 600, window_.y + 480 + kHudHeight / 2));
    xdotool("key q");
    const auto status = preview.waitExit(15s);
    ASSERT_TRUE(status) << "q did not quit";
    EXPECT_EQ(*status, 0) << preview.log();
    const auto final = preview.waitFor(std::regex(R"(final focus ([0-9.]+) m \(auto)"), 1s);
    ASSERT_TRUE(final) << preview.log();
    EXPECT_NEAR(std::stod((*final)[1]), tapDepth, 0.01 * tapDepth);
    cv::imwrite((scratch / "composite.png").string(), composite);
    cv::imwrite((scratch / "coc.png").string(), coc);
    cv::imwrite((scratch / "refocused.png").string(), refocused);
}

} // namespace
} // namespace defocus
