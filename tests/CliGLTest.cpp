// SPDX-License-Identifier: LGPL-2.1-or-later
// The defocus program end to end: Ctrl-C (SIGINT) and SIGTERM leave nothing under the output's
// name (--keep-partial keeps the frames so far beside it), every input frame gives an output frame, frames and focus chosen over time, and the depth-scale warning.
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include "defocus/Filter.hpp"
#include "defocus/Source.hpp"
#include "samples/FocusSchedule.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/ImageCompare.hpp"
#include "tests/TestSupport.hpp"

extern char** environ;

namespace defocus {
namespace {

namespace fs = std::filesystem;

class Cli : public test::GLTest {};

/// A folder pair of `count` frames made of links to the bundled TUM pairs, in order.
fs::path longClip(const std::string& name, int count)
{
    const fs::path dir = test::scratchDir(name);
    fs::create_directories(dir / "rgb");
    fs::create_directories(dir / "depth");
    std::vector<fs::path> rgb, depth;
    for (const auto& e : fs::directory_iterator(test::dataDir() / "tum_fr1_rpy" / "rgb"))
        rgb.push_back(e.path());
    for (const auto& e : fs::directory_iterator(test::dataDir() / "tum_fr1_rpy" / "depth"))
        depth.push_back(e.path());
    std::sort(rgb.begin(), rgb.end());
    std::sort(depth.begin(), depth.end());
    for (int i = 0; i < count; ++i) {
        const auto n = static_cast<std::size_t>(i) % rgb.size();
        char stem[32];
        std::snprintf(stem, sizeof stem, "%05d.png", i);
        fs::create_symlink(rgb[n], dir / "rgb" / stem);
        fs::create_symlink(depth[n], dir / "depth" / stem);
    }
    return dir;
}

struct ProgramRun {
    int exitCode = -1;
    std::string output;
};

/// Runs defocus with `args`, sends `signal` once `ready()` is true (0: never), and waits.
template <typename Ready>
ProgramRun runDefocus(const std::vector<std::string>& args, int signal, Ready ready, const fs::path& log)
{
    std::vector<std::string> all{std::string(DEFOCUS_BINARY_DIR) + "/defocus"};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    pid_t pid = 0;
    EXPECT_EQ(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
    int status = 0;
    bool exited = false;
    if (signal != 0) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
        while (!ready() && std::chrono::steady_clock::now() < deadline && !exited) {
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
            exited = waitpid(pid, &status, WNOHANG) == pid;
        }
        if (!exited)
            kill(pid, signal);
    }
    if (!exited)
        waitpid(pid, &status, 0);
    ProgramRun run;
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::ifstream in(log);
    run.output.assign(std::istreambuf_iterator<char>(in), {});
    return run;
}

/// "N frames out" from the summary line.
long framesOut(const std::string& output)
{
    const auto at = output.find(" frames out");
    if (at == std::string::npos)
        return -1;
    const auto start = output.rfind(' ', at - 1);
    return std::stol(output.substr(start + 1, at - start - 1));
}

class Interrupt : public Cli, public ::testing::WithParamInterface<int> {};

// Defect caught: a clip stopped by Ctrl-C or SIGTERM left under the output's final name (a shorter
// video that looks finished), a wrong exit status, or --keep-partial losing frames that were counted
// as written (every one of them must play back from OUTPUT.partial.mp4).
TEST_P(Interrupt, StoppedClipIsKeptOnlyAsPartialWhenAsked)
{
    // Own folders per signal: CTest runs the two instances in parallel.
    const std::string suffix = std::to_string(GetParam());
    const fs::path clip = longClip("interrupt_clip_" + suffix, 200);
    const fs::path dir = test::scratchDir("interrupt_out_" + suffix);
    for (const bool keep : {false, true}) {
        const fs::path out = dir / (keep ? "kept.mp4" : "clip.mp4");
        const fs::path temporary = dir / (keep ? ".kept.partial.mp4" : ".clip.partial.mp4");
        const fs::path partial = dir / (keep ? "kept.partial.mp4" : "clip.partial.mp4");
        std::vector<std::string> args{(clip / "rgb").string(), "--depth", (clip / "depth").string(), "--depth-scale",
                                      "5000", "-o", out.string(), "--focus", "1"};
        if (keep)
            args.push_back("--keep-partial");
        // Signal once a few frames are in the container.
        const ProgramRun run = runDefocus(
            args, GetParam(), [&] { return fs::exists(temporary) && fs::file_size(temporary) > 20000; },
            dir / "log.txt");
        EXPECT_EQ(run.exitCode, GetParam() == SIGINT ? 130 : 143) << run.output; // 128 + the signal, as shells report it
        EXPECT_FALSE(fs::exists(out)) << run.output;
        EXPECT_FALSE(fs::exists(temporary)) << run.output;
        const long written = framesOut(run.output);
        EXPECT_GT(written, 0) << run.output;
        EXPECT_LT(written, 200) << "the signal came before the end";
        if (!keep) {
            EXPECT_FALSE(fs::exists(partial)) << run.output;
            EXPECT_NE(run.output.find("nothing written to " + out.string()), std::string::npos) << run.output;
            continue;
        }
        EXPECT_NE(run.output.find("the frames so far are in " + partial.string()), std::string::npos) << run.output;
        cv::VideoCapture video(partial.string());
        ASSERT_TRUE(video.isOpened()) << run.output;
        long decoded = 0;
        cv::Mat frame;
        while (video.read(frame))
            ++decoded;
        EXPECT_EQ(decoded, written) << "every frame counted as written must play back";
    }
}

INSTANTIATE_TEST_SUITE_P(Signals, Interrupt, ::testing::Values(SIGINT, SIGTERM),
                         [](const auto& param) { return param.param == SIGINT ? "SIGINT" : "SIGTERM"; });

TEST_F(Cli, EveryInputFrameGivesAnOutputFrame)
{
    const fs::path out = test::scratchDir("cli_sequence");
    const ProgramRun run = runDefocus({(test::dataDir() / "tum_fr1_rpy").string(), "-o", (out / "frames/").string(), "-q"}, 0,
                               [] { return true; }, out / "log.txt");
    EXPECT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("10 frames in, 10 frames out"), std::string::npos) << run.output;
    long files = 0;
    for (const auto& e : fs::directory_iterator(out / "frames"))
        files += e.path().extension() == ".png" ? 1 : 0;
    EXPECT_EQ(files, 10);
}

// Defect caught: --start/--every taking the wrong frames, or keyed focus evaluated at the wrong
// time (frame index instead of the clip's timestamps) or not eased: the focus of every frame out
// is held against FocusSchedule at that frame's TUM timestamp.
TEST_F(Cli, StartEveryAndKeyedFocusPerFrame)
{
    const fs::path out = test::scratchDir("cli_keyed");
    const ProgramRun run = runDefocus({(test::dataDir() / "tum_fr1_rpy").string(), "-o", (out / "frames/").string(), "-q",
                                       "--start", "2", "--every", "3", "--focus", "0s:1,0.3s:2.5", "--explain"},
                                      0, [] { return true; }, out / "log.txt");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("3 frames in, 3 frames out"), std::string::npos) << run.output;
    std::ifstream list(test::dataDir() / "tum_fr1_rpy" / "rgb.txt");
    std::vector<double> times;
    for (std::string line; std::getline(list, line);)
        if (!line.empty() && line[0] != '#')
            times.push_back(std::stod(line));
    const FocusSchedule pull = FocusSchedule::parse("0s:1,0.3s:2.5");
    for (const std::size_t index : {2u, 5u, 8u}) {
        const std::string want = fmt::format("frame {}: focus {:.4f} m", index, pull.focusAt(times[index] - times[0]));
        EXPECT_NE(run.output.find(want), std::string::npos) << want << "\n" << run.output;
    }
    EXPECT_EQ(run.output.find("frame 3: focus"), std::string::npos) << run.output;
}

// Defect caught: a clip in the TUM layout whose depth is in millimetres (as RealSense recorders
// write it) read at TUM's 5000 units per metre without a word: every depth 5x too near.
TEST_F(Cli, MillimetreClipInTumLayoutWarnsWithTheFix)
{
    const fs::path clip = test::scratchDir("cli_millimetres");
    const fs::path tum = test::dataDir() / "tum_fr1_rpy";
    for (const char* list : {"rgb.txt", "depth.txt", "associations.txt"})
        fs::copy_file(tum / list, clip / list);
    fs::create_directory_symlink(tum / "rgb", clip / "rgb");
    fs::create_directories(clip / "depth");
    for (const auto& e : fs::directory_iterator(tum / "depth")) {
        const cv::Mat units = cv::imread(e.path().string(), cv::IMREAD_UNCHANGED);
        cv::Mat millimetres;
        units.convertTo(millimetres, CV_16U, 1000.0 / 5000.0);
        cv::imwrite((clip / "depth" / e.path().filename()).string(), millimetres);
    }
    const fs::path out = test::scratchDir("cli_millimetres_out");
    const ProgramRun warned = runDefocus({clip.string(), "-o", (out / "a.png").string(), "--frames", "1"}, 0,
                                         [] { return true; }, out / "log.txt");
    EXPECT_EQ(warned.exitCode, 0) << warned.output;
    EXPECT_NE(warned.output.find("defocus: warning: depth of "), std::string::npos) << warned.output;
    EXPECT_NE(warned.output.find("at 5000 units per metre"), std::string::npos) << warned.output;
    EXPECT_NE(warned.output.find("add --depth-scale 1000"), std::string::npos) << warned.output;
    const ProgramRun fixed = runDefocus({clip.string(), "-o", (out / "b.png").string(), "--frames", "1", "--depth-scale",
                                         "1000"},
                                        0, [] { return true; }, out / "log2.txt");
    EXPECT_EQ(fixed.exitCode, 0) << fixed.output;
    EXPECT_EQ(fixed.output.find("units per metre"), std::string::npos) << fixed.output;
    // The bundled clip itself, at its own scale, passes quietly.
    const ProgramRun tumRun = runDefocus({tum.string(), "-o", (out / "c.png").string(), "--frames", "1"}, 0,
                                         [] { return true; }, out / "log3.txt");
    EXPECT_EQ(tumRun.output.find("units per metre"), std::string::npos) << tumRun.output;
}

} // namespace
} // namespace defocus

namespace defocus {
namespace {

// Defect caught: the command line's frames in flight written under another frame's name, out of
// order, or other than the library gives one frame at a time (two stay submitted; an odd count
// of frames leaves one to drain at the end).
TEST_F(Cli, FramesInFlightAreWrittenAsTheLibraryFiltersEachFrame)
{
    const fs::path dir = test::scratchDir("CliGL_in_flight");
    const fs::path clip = test::dataDir() / "tum_fr1_rpy";
    const auto run = test::runDefocus(fmt::format("'{}' -o '{}/' --focus 1.0 --frames 7 -q", clip.string(),
                                                  (dir / "out").string()));
    ASSERT_EQ(run.exitCode, 0) << run.output;
    SourceSettings input;
    input.input = clip.string();
    Source source(input);
    Settings settings;
    settings.lens.focusM = 1.0;
    Filter filter(settings);
    for (int k = 0; k < 7; ++k) {
        const std::optional<Frame> frame = source.next();
        ASSERT_TRUE(frame);
        const cv::Mat expected = filter.process(frame->color, frame->depth, frame->timestampS);
        const fs::path written = dir / "out" / fs::path(frame->name).filename();
        EXPECT_TRUE(test::identical(cv::imread(written.string(), cv::IMREAD_COLOR), expected)) << written;
    }
}

} // namespace
} // namespace defocus
