// Bad input and a failure in the middle of a clip, through the defocus binary: the
// message names the frame's file, the exit status is 1, and the frames before it are kept as
// complete files (a shorter but playable video, or the sequence's first frames), with no
// temporary file left. Needs an EGL context to render the frames before the failure.
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

TEST_F(BadInputCliGLTest, BrokenFrameMidClipKeepsThePlayableVideoBeforeIt)
{
    const fs::path dir = makeClipWithBrokenFrame("CliGL_midclip_video");
    const fs::path video = dir / "out" / "clip.avi";
    fs::create_directory(dir / "out"); // defocus makes no missing folder above a file output
    const CliResult r = runDefocus(fmt::format("'{}' --depth '{}' --focus 1 -o '{}'", (dir / "rgb").string(),
                                               (dir / "depth").string(), video.string()));
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("cannot read colour image '" + (dir / "rgb" / "3.png").string() + "': truncated PNG"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("frame 3: cannot read colour image"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("3 frames in, 3 frames out"), std::string::npos) << r.output;
    EXPECT_EQ(fileNames(dir / "out"), std::vector<std::string>{"clip.avi"}) << r.output; // no clip.partial.avi

    cv::VideoCapture capture(video.string());
    ASSERT_TRUE(capture.isOpened()) << r.output;
    int frames = 0;
    for (cv::Mat frame; capture.read(frame); ++frames)
        EXPECT_EQ(frame.size(), cv::Size(64, 48));
    EXPECT_EQ(frames, 3);
}

TEST_F(BadInputCliGLTest, BrokenFrameMidClipKeepsTheSequenceBeforeIt)
{
    const fs::path dir = makeClipWithBrokenFrame("CliGL_midclip_sequence");
    const CliResult r = runDefocus(fmt::format("'{}' --depth '{}' --focus 1 -o '{}/'", (dir / "rgb").string(),
                                               (dir / "depth").string(), (dir / "out").string()));
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find((dir / "rgb" / "3.png").string()), std::string::npos) << r.output;
    // The input's frame names, listed: the sequence is a TUM folder of the frames before the bad one.
    EXPECT_EQ(fileNames(dir / "out"), (std::vector<std::string>{"0.png", "1.png", "2.png", "associations.txt", "depth",
                                                               "depth.txt", "rgb.txt"}))
        << r.output;
    for (int k = 0; k < 3; ++k)
        EXPECT_EQ(cv::imread((dir / "out" / fmt::format("{}.png", k)).string()).size(), cv::Size(64, 48));
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
