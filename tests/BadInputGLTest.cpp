// SPDX-License-Identifier: LGPL-2.1-or-later
// Bad input and a failure in the middle of a clip, through the defocus binary: the message names
// the frame's file, the exit status is 1, nothing is written under the output's name (an earlier
// output there stays) and no temporary file is left; with --keep-partial the frames before it are
// kept as OUTPUT.partial. Needs an EGL context to render the frames before the failure.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

using test::CliResult;
using test::runDefocus;

std::vector<std::string> fileNames(const fs::path& dir)
{
    std::vector<std::string> names;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

// Five 64x48 colour frames with depth; frame 3's colour file is cut in half.
fs::path makeClipWithBrokenFrame(const std::string& name)
{
    const fs::path dir = test::scratchDir(name);
    fs::create_directories(dir / "rgb");
    fs::create_directories(dir / "depth");
    for (int k = 0; k < 5; ++k) {
        cv::Mat colour(48, 64, CV_8UC3);
        cv::randu(colour, 0, 255);
        EXPECT_TRUE(cv::imwrite((dir / "rgb" / fmt::format("{}.png", k)).string(), colour));
        EXPECT_TRUE(cv::imwrite((dir / "depth" / fmt::format("{}.png", k)).string(),
                                cv::Mat(48, 64, CV_16UC1, cv::Scalar(1000.0 + 500.0 * k))));
    }
    const fs::path broken = dir / "rgb" / "3.png";
    std::ifstream in(broken, std::ios::binary);
    const std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    in.close();
    std::ofstream(broken, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
    return dir;
}

using BadInputCliGLTest = test::GLTest;

// A copy of the bundled TUM clip (10 frames, 640x480) whose frame 5 colour file is cut in half;
// returns the folder and sets `broken` to that file.
fs::path tumClipWithBrokenFrame5(const std::string& name, fs::path& broken)
{
    const fs::path dir = test::scratchDir(name) / "clip";
    fs::copy(test::dataDir() / "tum_fr1_rpy", dir, fs::copy_options::recursive);
    std::ifstream list(dir / "associations.txt");
    std::vector<std::string> colour;
    for (std::string line; std::getline(list, line);)
        if (!line.empty() && line[0] != '#')
            colour.push_back(line.substr(line.find(' ') + 1, line.find(' ', line.find(' ') + 1) - line.find(' ') - 1));
    EXPECT_EQ(colour.size(), 10u);
    broken = dir / colour.at(5);
    std::ifstream in(broken, std::ios::binary);
    const std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    in.close();
    std::ofstream(broken, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
    return dir;
}

std::string contents(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Defect caught: a clip that fails at a corrupt frame leaves its first frames under the output's
// final name (a shorter video, a folder listing 5 of 10 frames, frame 4 as the image), where they
// look like a finished result, and with -y in place of a good earlier output; or a temporary
// file or folder left beside it; and the same of the contact sheet and the timings beside a clip.
// Each output kind: the error names the frame's file, exit 1, the earlier outputs untouched,
// nothing else in their folder.
TEST_F(BadInputCliGLTest, BrokenFrameMidClipLeavesTheEarlierOutputUntouched)
{
    fs::path broken;
    const fs::path clip = tumClipWithBrokenFrame5("CliGL_midclip_untouched", broken);
    const fs::path out = clip.parent_path() / "out";
    fs::create_directories(out / "tb");
    std::ofstream(out / "tb.mp4") << "an earlier good video";
    std::ofstream(out / "tb.png") << "an earlier good image";
    std::ofstream(out / "tb" / "rgb.txt") << "# an earlier good sequence\n1.0 1.png\n";
    std::ofstream(out / "tb" / "1.png") << "an earlier good frame";
    std::ofstream(out / "sheet.png") << "an earlier good sheet";
    std::ofstream(out / "t.json") << "earlier good timings";
    for (const std::string output : {"tb.mp4", "tb/", "tb.png"}) {
        // One image holds one frame: the broken one, chosen with --start. A clip has its contact
        // sheet (frame 2, before the broken one) and its timings beside it.
        const std::string frames = output == "tb.png" ? "--start 5 --frames 1 "
                                                      : fmt::format("--contact-sheet '{}' --contact-frame 2 --timings '{}' ",
                                                                    (out / "sheet.png").string(), (out / "t.json").string());
        const CliResult r = runDefocus(fmt::format("'{}' --focus 1 --quality fast {}-y -o '{}'", clip.string(),
                                                   frames, (out / output).string()));
        EXPECT_EQ(r.exitCode, 1) << output << "\n" << r.output;
        // Named as the clip counts its frames, --start or not.
        EXPECT_NE(r.output.find("frame 5: cannot read colour image '" + broken.string()), std::string::npos)
            << r.output;
        EXPECT_EQ(fileNames(out), (std::vector<std::string>{"sheet.png", "t.json", "tb", "tb.mp4", "tb.png"})) << output;
        EXPECT_EQ(fileNames(out / "tb"), (std::vector<std::string>{"1.png", "rgb.txt"})) << output;
    }
    EXPECT_EQ(contents(out / "tb.mp4"), "an earlier good video");
    EXPECT_EQ(contents(out / "tb.png"), "an earlier good image");
    EXPECT_EQ(contents(out / "sheet.png"), "an earlier good sheet");
    EXPECT_EQ(contents(out / "t.json"), "earlier good timings");
    EXPECT_EQ(contents(out / "tb" / "rgb.txt"), "# an earlier good sequence\n1.0 1.png\n");
}

// Defect caught: --keep-partial losing the frames before the failure, keeping them under the
// final name, or keeping a video that does not play them all.
TEST_F(BadInputCliGLTest, BrokenFrameMidClipWithKeepPartialKeepsTheFramesBeforeIt)
{
    fs::path broken;
    const fs::path clip = tumClipWithBrokenFrame5("CliGL_midclip_keep", broken);
    const fs::path out = clip.parent_path() / "out";
    fs::create_directories(out); // defocus makes no missing folder above a file output
    // (A one-image output holds one frame, so no frame comes before a broken one there; the
    // sinks' test keeps a partial image, FileSinks.AbandonLeavesTheFinalNameAloneAndKeepsThePartialOnlyWhenAsked.)
    for (const std::string output : {"tb.mp4", "tb/"}) {
        const CliResult r = runDefocus(fmt::format("'{}' --focus 1 --quality fast --keep-partial -o '{}'",
                                                   clip.string(), (out / output).string()));
        EXPECT_EQ(r.exitCode, 1) << output << "\n" << r.output;
        EXPECT_NE(r.output.find("5 frames in, 5 frames out"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("the frames before the error are in"), std::string::npos) << r.output;
    }
    EXPECT_EQ(fileNames(out), (std::vector<std::string>{"tb.partial", "tb.partial.mp4"}));
    cv::VideoCapture capture((out / "tb.partial.mp4").string());
    ASSERT_TRUE(capture.isOpened());
    int frames = 0;
    for (cv::Mat frame; capture.read(frame); ++frames)
        EXPECT_EQ(frame.size(), cv::Size(640, 480));
    EXPECT_EQ(frames, 5);
    std::ifstream list(out / "tb.partial" / "rgb.txt");
    int listed = 0;
    for (std::string line; std::getline(list, line);)
        if (!line.empty() && line[0] != '#') {
            ++listed;
            EXPECT_TRUE(fs::exists(out / "tb.partial" / line.substr(line.find(' ') + 1))) << line;
        }
    EXPECT_EQ(listed, 5);
}

TEST_F(BadInputCliGLTest, BrokenFirstFrameLeavesNoOutputAtAll)
{
    const fs::path dir = makeClipWithBrokenFrame("CliGL_first_frame");
    fs::copy_file(dir / "rgb" / "3.png", dir / "rgb" / "0.png", fs::copy_options::overwrite_existing);
    for (const std::string output : {"out.mp4", "frames/"}) {
        const CliResult r = runDefocus(fmt::format("'{}' --depth '{}' --focus 1 -o '{}'", (dir / "rgb").string(),
                                                   (dir / "depth").string(), (dir / output).string()));
        EXPECT_EQ(r.exitCode, 1) << r.output;
        EXPECT_NE(r.output.find((dir / "rgb" / "0.png").string()), std::string::npos) << r.output;
    }
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"depth", "rgb"}));
}

} // namespace
} // namespace defocus
