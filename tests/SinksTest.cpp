// SPDX-License-Identifier: LGPL-2.1-or-later
// Frame sinks: sequences in the TUM layout, videos of each codec read back with cv::VideoCapture,
// single images, existing outputs refused without overwrite, and the errors for bad outputs.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <chrono>
#include <thread>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "sinks/BackgroundSink.hpp"
#include "sinks/FrameSink.hpp"
#include "sinks/ImageSinks.hpp"
#include "sources/ImageIO.hpp"
#include "sources/FrameSource.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

cv::Mat readBack(const fs::path& file)
{
    enableOpenExr();
    return cv::imread(file.string(), cv::IMREAD_UNCHANGED);
}

// A frame that differs per index and has structure (a gradient), so a wrong or repeated frame
// shows up.
cv::Mat testFrame(int index, cv::Size size = {64, 48})
{
    cv::Mat frame(size, CV_8UC3);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x)
            frame.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(30 * index + 20),
                                                  static_cast<uchar>(2 * x + 40),
                                                  static_cast<uchar>(3 * y + 30));
    return frame;
}

std::vector<std::string> fileNames(const fs::path& dir)
{
    std::vector<std::string> names;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

std::string openError(const SinkOptions& options)
{
    try {
        openSink(options);
    } catch (const SinkError& e) {
        return e.what();
    }
    ADD_FAILURE() << "openSink(" << options.output << ") did not throw SinkError";
    return {};
}

// Defect caught: frames without an input name written under another name, or no rgb.txt.
TEST(ImageSequenceSink, FramesWithoutInputNamesAreNumberedAndListed)
{
    const fs::path dir = test::scratchDir("Sink_sequence") / "out";
    const std::unique_ptr<FrameSink> sink = openSink({dir.string() + "/", 30.0, false});
    EXPECT_FALSE(fs::exists(dir)); // the frames go to a hidden folder beside it until finish()
    EXPECT_TRUE(fs::is_directory(temporaryPath(dir, true)));
    EXPECT_EQ(sink->encoding(), SinkEncoding::Srgb8);
    for (int k = 0; k < 3; ++k)
        sink->write(testFrame(k));
    sink->finish();
    EXPECT_EQ(sink->framesWritten(), 3u);
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"frame_000000.png", "frame_000001.png",
                                                        "frame_000002.png", "rgb.txt"}));
    for (int k = 0; k < 3; ++k) {
        const cv::Mat back = readBack(dir / fmt::format("frame_{:06}.png", k));
        ASSERT_EQ(back.type(), CV_8UC3);
        EXPECT_EQ(cv::norm(back, testFrame(k), cv::NORM_INF), 0.0); // PNG is lossless
    }
}

TEST(ImageSequenceSink, ExistingFolderWithoutSlashAndLinearExrSequence)
{
    const fs::path dir = test::scratchDir("Sink_sequence_exr");
    const std::unique_ptr<FrameSink> sink = openSink({dir, 30.0, true});
    EXPECT_EQ(sink->encoding(), SinkEncoding::Linear32F);
    const cv::Mat hdr(8, 8, CV_32FC3, cv::Scalar(0.5, 4.0, 80.0));
    sink->write(hdr);
    sink->write(hdr * 2.0);
    sink->finish();
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"frame_000000.exr", "frame_000001.exr", "rgb.txt"}));
    const cv::Mat back = readBack(dir / "frame_000001.exr");
    ASSERT_EQ(back.type(), CV_32FC3);
    EXPECT_EQ(back.at<cv::Vec3f>(7, 7), cv::Vec3f(1.0f, 8.0f, 160.0f));
}

TEST(ImageSequenceSink, WrongFrameTypeIsASinkError)
{
    const fs::path dir = test::scratchDir("Sink_sequence_type");
    const std::unique_ptr<FrameSink> sink = openSink({dir, 30.0, false});
    EXPECT_THROW(sink->write(cv::Mat(4, 4, CV_32FC3)), SinkError);
    EXPECT_THROW(sink->write(cv::Mat()), SinkError);
    EXPECT_EQ(sink->framesWritten(), 0u);
}

TEST(ImageSequenceSink, FolderItCreatedIsRemovedWhenNoFrameWasWritten)
{
    const fs::path dir = test::scratchDir("Sink_sequence_unused");
    openSink({dir.string() + "/new/", 30.0, false})->finish();
    EXPECT_FALSE(fs::exists(dir / "new")); // a failed run leaves no empty output folder

    const std::unique_ptr<FrameSink> existing = openSink({dir, 30.0, false});
    existing->finish();
    EXPECT_TRUE(fs::is_directory(dir)); // one that was there before stays

    const std::unique_ptr<FrameSink> used = openSink({dir / "used/", 30.0, false});
    used->write(testFrame(0));
    used->finish();
    used->finish();
    EXPECT_EQ(fileNames(dir / "used"), (std::vector<std::string>{"frame_000000.png", "rgb.txt"}));
    EXPECT_NE(used->describe().find("1 frames"), std::string::npos) << used->describe();
}

// Defect caught: a sequence output that is not a TUM folder again (frames renamed, timestamps
// lost, depth or lists missing), so defocus cannot read its own output.
TEST(ImageSequenceSink, KeepsTheInputsFrameNamesAndIsATumFolderAgain)
{
    const fs::path dir = test::scratchDir("Sink_sequence_tum") / "out";
    const std::unique_ptr<FrameSink> sink = openSink({dir.string() + "/", 30.0, false});
    const std::vector<double> times{1305031102.175304, 1305031102.211214};
    for (int k = 0; k < 2; ++k) {
        Frame origin;
        origin.index = static_cast<std::size_t>(k);
        origin.timestampS = times[static_cast<std::size_t>(k)];
        origin.name = fmt::format("rgb/{:.6f}.png", origin.timestampS);
        origin.depth = cv::Mat(48, 64, CV_32FC1, cv::Scalar(1.0 + k)); // 1 m, then 2 m
        origin.depth.at<float>(0, 0) = 0.0f;                          // a hole stays a hole
        sink->writeFrame(testFrame(k), origin);
    }
    sink->finish();
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"1305031102.175304.png", "1305031102.211214.png",
                                                        "associations.txt", "depth", "depth.txt", "rgb.txt"}));
    const std::unique_ptr<FrameSource> again = openSource({dir, std::nullopt, std::nullopt});
    for (int k = 0; k < 2; ++k) {
        const std::optional<Frame> frame = again->next();
        ASSERT_TRUE(frame);
        EXPECT_NEAR(frame->timestampS, times[static_cast<std::size_t>(k)], 1e-6);
        EXPECT_EQ(cv::norm(frame->color, testFrame(k), cv::NORM_INF), 0.0);
        EXPECT_FLOAT_EQ(frame->depth.at<float>(10, 10), static_cast<float>(1 + k));
        EXPECT_FALSE(frame->depth.at<float>(0, 0) > 0.0f);
    }
    EXPECT_FALSE(again->next());
}

// Defect caught: an existing output silently replaced (ffmpeg refuses without -y).
TEST(OpenSink, ExistingOutputIsRefusedWithoutOverwrite)
{
    const fs::path dir = test::scratchDir("Sink_overwrite");
    for (const std::string name : {"clip.mp4", "one.png"}) {
        std::ofstream(dir / name) << "precious";
        const std::string error = openError({dir / name, 30.0, false});
        EXPECT_NE(error.find((dir / name).string()), std::string::npos) << error;
        EXPECT_NE(error.find("-y"), std::string::npos) << error;
        EXPECT_EQ(fs::file_size(dir / name), 8u) << "refused, and left as it was";
        SinkOptions options{dir / name, 30.0, false};
        options.overwrite = true;
        EXPECT_NO_THROW(openSink(options));
    }
    fs::create_directories(dir / "frames");
    std::ofstream(dir / "frames" / "old.png") << "x";
    EXPECT_NE(openError({dir / "frames/", 30.0, false}).find("not empty"), std::string::npos);
    fs::create_directories(dir / "empty");
    EXPECT_NO_THROW(openSink({dir / "empty/", 30.0, false})); // an empty folder is no output yet
}

// Writes `count` frames and reads the file back: frame count, size and (lossy) content.
void checkVideoRoundTrip(const std::string& extension, const std::string& expectedCodec)
{
    const fs::path dir = test::scratchDir("Sink_video_" + extension);
    const fs::path file = dir / ("clip." + extension);
    constexpr int count = 7;
    {
        const std::unique_ptr<FrameSink> sink = openSink({file, 24.0, false});
        EXPECT_EQ(sink->encoding(), SinkEncoding::Srgb8);
        if (!expectedCodec.empty()) {
            EXPECT_NE(sink->describe().find(expectedCodec), std::string::npos)
                << sink->describe();
        }
        for (int k = 0; k < count; ++k)
            sink->write(testFrame(k));
        EXPECT_EQ(sink->framesWritten(), static_cast<std::size_t>(count));
        EXPECT_FALSE(fs::exists(file)); // still the partial file until finish()
        sink->finish();
        sink->finish(); // idempotent
    }
    EXPECT_EQ(fileNames(dir), std::vector<std::string>{"clip." + extension});

    cv::VideoCapture capture(file.string());
    ASSERT_TRUE(capture.isOpened()) << file;
    EXPECT_NEAR(capture.get(cv::CAP_PROP_FPS), 24.0, 0.01);
    int read = 0;
    for (cv::Mat frame; capture.read(frame); ++read) {
        ASSERT_EQ(frame.size(), cv::Size(64, 48));
        // Lossy codecs: compare means. Consecutive frames differ by 30 in blue, so a tolerance of
        // 8 still tells every frame apart.
        const cv::Scalar got = cv::mean(frame);
        const cv::Scalar want = cv::mean(testFrame(read));
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(got[c], want[c], 8.0) << "frame " << read << " channel " << c;
    }
    EXPECT_EQ(read, count);
}

TEST(VideoSink, Mp4IsH264AndReadsBackEveryFrame)
{
    checkVideoRoundTrip("mp4", "h264 (avc1)");
}

TEST(VideoSink, AviWithMjpgReadsBackEveryFrame)
{
    checkVideoRoundTrip("avi", "MJPG");
}

TEST(VideoSink, MkvIsFfv1AndReadsBackEveryFrame)
{
    checkVideoRoundTrip("mkv", "ffv1 (FFV1)");
}

TEST(VideoSink, WebmIsVp9AndReadsBackEveryFrame)
{
    checkVideoRoundTrip("webm", "vp9 (VP90)");
}

// PSNR of `decoded` against `original`, 8-bit, over all channels; +inf when identical.
double psnr(const cv::Mat& original, const cv::Mat& decoded)
{
    const double mse = cv::norm(original, decoded, cv::NORM_L2SQR) / static_cast<double>(original.total() * 3);
    return mse == 0.0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(255.0 * 255.0 / mse);
}

// Defect caught: a codec that drops or repeats frames, swaps colour channels, shifts the chroma
// or loses more than its default quality; FFV1 not lossless. Every codec encodes the bundled
// clip's 10 frames (640x480) and each frame decoded is held against the frame written: lossy
// codecs at >= 28 dB each (on these raw camera frames, noisy and detailed, they measure 30-35 dB at
// FFmpeg's defaults; a frame with its red and blue swapped measures far less, checked below),
// FFV1 bit-exact. Prints each codec's mean and worst PSNR and its size.
TEST(VideoSink, EveryCodecDecodesEveryFrameAtItsQuality)
{
    std::vector<cv::Mat> clip;
    for (const auto& entry : fs::directory_iterator(test::dataDir() / "tum_fr1_rpy" / "rgb"))
        clip.push_back(cv::imread(entry.path().string(), cv::IMREAD_COLOR));
    ASSERT_EQ(clip.size(), 10u);
    const fs::path dir = test::scratchDir("Sink_codecs");
    const std::vector<std::pair<std::string, std::string>> codecs{
        {"h264", "mp4"}, {"mp4v", "mp4"}, {"vp9", "webm"}, {"ffv1", "mkv"}, {"mjpg", "avi"}};
    for (const auto& [codec, container] : codecs) {
        const fs::path file = dir / (codec + "." + container);
        SinkOptions options(file, 30.0);
        options.codec = codec;
        {
            const std::unique_ptr<FrameSink> sink = openSink(options);
            for (const cv::Mat& frame : clip)
                sink->write(frame);
            sink->finish();
        }
        cv::VideoCapture capture(file.string());
        ASSERT_TRUE(capture.isOpened()) << file;
        std::size_t read = 0;
        double sum = 0.0, worst = std::numeric_limits<double>::infinity();
        for (cv::Mat frame; capture.read(frame); ++read) {
            ASSERT_LT(read, clip.size()) << codec << ": more frames than written";
            const double db = psnr(clip[read], frame);
            if (codec == "ffv1") {
                EXPECT_TRUE(std::isinf(db)) << "ffv1 frame " << read << ": " << db << " dB, not lossless";
            } else {
                EXPECT_GE(db, 28.0) << codec << " frame " << read;
                sum += db;
                worst = std::min(worst, db);
            }
        }
        EXPECT_EQ(read, clip.size()) << codec;
        std::printf("codec %s (.%s): %zu frames, PSNR %s, %ju bytes\n", codec.c_str(), container.c_str(), read,
                    codec == "ffv1" ? "lossless"
                                    : fmt::format("mean {:.2f} dB, worst frame {:.2f} dB", sum / static_cast<double>(read),
                                                  worst)
                                          .c_str(),
                    static_cast<std::uintmax_t>(fs::file_size(file)));
    }
    // What the threshold separates from: the first frame with red and blue swapped.
    cv::Mat swapped;
    cv::cvtColor(clip[0], swapped, cv::COLOR_BGR2RGB);
    std::printf("red and blue swapped: %.2f dB\n", psnr(clip[0], swapped));
    EXPECT_LT(psnr(clip[0], swapped), 28.0);
}

TEST(VideoSink, FrameOfAnotherSizeIsASinkError)
{
    const fs::path file = test::scratchDir("Sink_video_size") / "clip.mp4";
    const std::unique_ptr<FrameSink> sink = openSink({file, 30.0, false});
    sink->write(testFrame(0));
    try {
        sink->write(testFrame(1, {32, 48}));
        ADD_FAILURE() << "no SinkError for a frame of another size";
    } catch (const SinkError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(file.string()), std::string::npos) << message;
        EXPECT_NE(message.find("32x48"), std::string::npos) << message;
        EXPECT_NE(message.find("64x48"), std::string::npos) << message;
    }
    EXPECT_THROW(sink->write(cv::Mat(48, 64, CV_32FC3)), SinkError);
    EXPECT_EQ(sink->framesWritten(), 1u);
}

// Defect caught: a sink destroyed without finish() (an exception unwinding the run) putting a
// shorter video under the output's name.
TEST(VideoSink, DestructorWithoutFinishLeavesNoFile)
{
    const fs::path dir = test::scratchDir("Sink_video_dtor");
    {
        const std::unique_ptr<FrameSink> sink = openSink({dir / "clip.avi", 30.0, false});
        sink->write(testFrame(0));
        sink->write(testFrame(1));
    }
    EXPECT_TRUE(fileNames(dir).empty());
}

std::string contents(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Defect caught: a failed or stopped run's frames put under the output's final name, or in place of
// an earlier output there (-y), or a temporary file or folder left beside it; and abandon(true)
// not keeping the frames written under NAME.partial. Each file output kind.
TEST(FileSinks, AbandonLeavesTheFinalNameAloneAndKeepsThePartialOnlyWhenAsked)
{
    const fs::path dir = test::scratchDir("Sink_abandon");
    std::ofstream(dir / "clip.avi") << "earlier video";
    std::ofstream(dir / "one.png") << "earlier image";
    fs::create_directories(dir / "seq");
    std::ofstream(dir / "seq" / "rgb.txt") << "earlier list";
    const std::vector<std::string> before{"clip.avi", "one.png", "seq"};
    for (const std::string output : {"clip.avi", "seq/", "one.png"}) {
        SinkOptions options{dir / output, 30.0, false};
        options.overwrite = true;
        {
            const std::unique_ptr<FrameSink> sink = openSink(options);
            sink->write(testFrame(0));
            sink->write(testFrame(1));
            EXPECT_TRUE(sink->abandon(false).empty()) << output;
            sink->finish(); // does nothing now
        }
        EXPECT_EQ(fileNames(dir), before) << output;
        const std::unique_ptr<FrameSink> sink = openSink(options);
        sink->write(testFrame(0));
        sink->write(testFrame(1));
        const fs::path kept = sink->abandon(true);
        EXPECT_EQ(kept, partialPath(dir / output, output == "seq/")) << output;
        EXPECT_TRUE(fs::exists(kept)) << output;
        fs::rename(kept, dir / "kept");
        EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"clip.avi", "kept", "one.png", "seq"})) << output;
        if (output == "clip.avi") {
            cv::VideoCapture capture((dir / "kept").string(), cv::CAP_FFMPEG);
            int read = 0;
            for (cv::Mat frame; capture.read(frame);)
                ++read;
            EXPECT_EQ(read, 2);
        } else if (output == "seq/") {
            EXPECT_EQ(fileNames(dir / "kept"), (std::vector<std::string>{"frame_000000.png", "frame_000001.png",
                                                                        "rgb.txt"}));
        } else {
            EXPECT_EQ(cv::norm(readBack(dir / "kept"), testFrame(1), cv::NORM_INF), 0.0);
        }
        fs::remove_all(dir / "kept");
    }
    EXPECT_EQ(contents(dir / "clip.avi"), "earlier video");
    EXPECT_EQ(contents(dir / "one.png"), "earlier image");
    EXPECT_EQ(fileNames(dir / "seq"), std::vector<std::string>{"rgb.txt"});
    EXPECT_EQ(contents(dir / "seq" / "rgb.txt"), "earlier list");
}

// Defect caught: -y into a folder that holds other files deleting them, a finished sequence not
// put in place over the earlier frames and lists, or the frames for a folder that exists written
// beside it (its parent may be another file system, as for a mount point, or not writable).
TEST(ImageSequenceSink, FinishIntoAFolderWithFilesReplacesItsFramesAndListsOnly)
{
    const fs::path dir = test::scratchDir("Sink_sequence_into");
    std::ofstream(dir / "notes.md") << "mine";
    std::ofstream(dir / "rgb.txt") << "earlier list";
    SinkOptions options{dir, 30.0, false};
    options.overwrite = true;
    const std::unique_ptr<FrameSink> sink = openSink(options);
    sink->write(testFrame(0));
    EXPECT_FALSE(fs::exists(temporaryPath(dir, true)));
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{".defocus.partial", "notes.md", "rgb.txt"}));
    sink->finish();
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"frame_000000.png", "notes.md", "rgb.txt"}));
    EXPECT_NE(contents(dir / "rgb.txt").find("frame_000000.png"), std::string::npos);
    EXPECT_FALSE(fs::exists(temporaryPath(dir, true)));
}

TEST(VideoSink, NoFramesLeavesNoFile)
{
    const fs::path dir = test::scratchDir("Sink_video_empty");
    openSink({dir / "clip.mp4", 30.0, false})->finish();
    EXPECT_TRUE(fileNames(dir).empty());
}

TEST(SingleImageSink, PngHoldsTheLastFrameWritten)
{
    const fs::path dir = test::scratchDir("Sink_single_png");
    const fs::path file = dir / "nested" / "out.png";
    fs::create_directory(dir / "nested"); // its folder must exist (OpenSink.MakesOnlyTheLastFolderOfAFolderOutput)
    const std::unique_ptr<FrameSink> sink = openSink({file, 30.0, false});
    EXPECT_EQ(sink->encoding(), SinkEncoding::Srgb8);
    sink->write(testFrame(0));
    sink->write(testFrame(1));
    sink->finish();
    EXPECT_EQ(sink->framesWritten(), 2u);
    EXPECT_EQ(fileNames(file.parent_path()), std::vector<std::string>{"out.png"}); // no temp left
    const cv::Mat back = readBack(file);
    ASSERT_EQ(back.type(), CV_8UC3);
    EXPECT_EQ(cv::norm(back, testFrame(1), cv::NORM_INF), 0.0);
}

TEST(SingleImageSink, ExrKeepsValuesAboveOneUnclipped)
{
    const fs::path file = test::scratchDir("Sink_single_exr") / "out.exr";
    const std::unique_ptr<FrameSink> sink = openSink({file, 30.0, false});
    EXPECT_EQ(sink->encoding(), SinkEncoding::Linear32F);
    cv::Mat hdr(5, 7, CV_32FC3, cv::Scalar(0.001, 1.0, 80.0));
    hdr.at<cv::Vec3f>(2, 3) = cv::Vec3f(1234.5f, 0.0f, 3.25f);
    sink->write(hdr);
    EXPECT_THROW(sink->write(cv::Mat(5, 7, CV_8UC3)), SinkError);
    sink->finish();
    const cv::Mat back = readBack(file);
    ASSERT_EQ(back.type(), CV_32FC3);
    EXPECT_EQ(cv::norm(back, hdr, cv::NORM_INF), 0.0); // 32-bit float EXR is exact
}

TEST(OpenSink, UnknownOrMissingExtensionIsASinkError)
{
    const fs::path dir = test::scratchDir("Sink_errors");
    const std::string unknown = openError({dir / "out.gif", 30.0, false});
    EXPECT_NE(unknown.find((dir / "out.gif").string()), std::string::npos) << unknown;
    EXPECT_NE(unknown.find(".gif"), std::string::npos) << unknown;
    const std::string none = openError({dir / "out", 30.0, false});
    EXPECT_NE(none.find("no extension"), std::string::npos) << none;
    const std::string fps = openError({dir / "out.mp4", 0.0, false});
    EXPECT_NE(fps.find("frame rate"), std::string::npos) << fps;
    EXPECT_TRUE(fileNames(dir).empty());
}

// Defect caught: a typo in an output's path creating the whole missing tree (-o /nonexistent/dir/
// x.mp4 made /nonexistent/dir/). A folder output's own last folder is made, nothing above it.
TEST(OpenSink, MakesOnlyTheLastFolderOfAFolderOutput)
{
    const fs::path dir = test::scratchDir("Sink_missing_folders");
    for (const fs::path& file : {dir / "typo" / "x.mp4", dir / "typo" / "x.png", dir / "typo" / "x.exr"}) {
        const std::string error = openError({file, 30.0, false});
        EXPECT_NE(error.find("folder '" + (dir / "typo").string() + "' does not exist"), std::string::npos) << error;
    }
    const std::string deeper = openError({dir.string() + "/typo/frames/", 30.0, false});
    EXPECT_NE(deeper.find("folder '" + (dir / "typo").string() + "' does not exist"), std::string::npos) << deeper;
    EXPECT_TRUE(fileNames(dir).empty());

    const std::unique_ptr<FrameSink> frames = openSink({dir.string() + "/frames/", 30.0, false});
    frames->write(testFrame(0));
    frames->finish();
    EXPECT_EQ(fileNames(dir / "frames"), (std::vector<std::string>{"frame_000000.png", "rgb.txt"}));
}

// The bytes of every regular file under `dir`, by path relative to it.
std::map<std::string, std::string> filesUnder(const fs::path& dir)
{
    std::map<std::string, std::string> files;
    for (const auto& entry : fs::recursive_directory_iterator(dir))
        if (entry.is_regular_file()) {
            std::ifstream in(entry.path(), std::ios::binary);
            files[fs::relative(entry.path(), dir).string()] = {std::istreambuf_iterator<char>(in), {}};
        }
    return files;
}

// Frame k of a clip with everything a sequence output keeps: the input's name and timestamp,
// depth in TUM's units, in another 16-bit scale, in metres, or none, and a name given twice.
Frame clipFrame(int k)
{
    Frame origin;
    origin.index = static_cast<std::size_t>(k);
    origin.timestampS = 1305031102.0 + 0.033 * k;
    origin.name = k == 5 ? "rgb/1305031102.099000.png" : fmt::format("rgb/{:.6f}.png", origin.timestampS);
    const cv::Mat metres(48, 64, CV_32FC1, cv::Scalar(0.5 + 0.25 * k));
    switch (k % 4) {
    case 0: metres.convertTo(origin.depth, CV_16UC1, 5000.0); origin.depthScale = 5000.0; break;
    case 1: metres.convertTo(origin.depth, CV_16UC1, 1000.0); origin.depthScale = 1000.0; break;
    case 2: origin.depth = metres; break;
    default: break; // no depth
    }
    return origin;
}

// Defects caught: frames encoded on several threads written under another frame's name or with
// its depth (a job given the wrong frame), lists in the order the encodes finished, frames
// without a name numbered by the frames written rather than by their place. The files and lists
// of 3 threads are those of one, byte for byte.
TEST(ImageSequenceSink, FramesEncodedSideBySideAreTheFilesOfOneAfterTheOther)
{
    const fs::path dir = test::scratchDir("Sink_sequence_threads");
    for (const std::size_t threads : {1u, 3u}) {
        ImageSequenceSink sink(dir / fmt::format("out{}", threads), false, 30.0, threads);
        for (int k = 0; k < 12; ++k) {
            // Larger frames take longer to encode: later frames may finish first.
            const cv::Size size = k % 3 == 0 ? cv::Size(320, 240) : cv::Size(64, 48);
            Frame origin = clipFrame(k);
            if (size.width != 64 && !origin.depth.empty())
                cv::resize(origin.depth, origin.depth, size, 0, 0, cv::INTER_NEAREST);
            if (k == 7)
                sink.write(testFrame(k, size)); // no input behind it: frame_000007
            else
                sink.writeFrame(testFrame(k, size), origin);
        }
        sink.finish();
        EXPECT_EQ(sink.framesWritten(), 12u);
    }
    const auto one = filesUnder(dir / "out1"), three = filesUnder(dir / "out3");
    EXPECT_EQ(one.size(), 12u + 9u + 3u) << "12 frames, 9 depth maps, 3 lists";
    ASSERT_EQ(one.size(), three.size());
    for (const auto& [name, bytes] : one) {
        ASSERT_TRUE(three.count(name)) << name;
        EXPECT_TRUE(three.at(name) == bytes) << name;
    }
    EXPECT_TRUE(one.count("frame_000007.png"));
}

// Defect caught: a folder's frames encoded one after the other whatever the threads (a thread
// pool that is never used). Frame 0's file is a FIFO that nothing reads yet, so its encoding
// waits; frame 1 is written meanwhile, yet counts as written only once frame 0 is.
TEST(ImageSequenceSink, FramesAreEncodedSideBySide)
{
    const fs::path dir = test::scratchDir("Sink_sequence_side_by_side") / "out";
    ImageSequenceSink sink(dir, false, 30.0, 2);
    const fs::path work = temporaryPath(dir, true);
    const fs::path fifo = work / ".frame_000000.partial.png";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    std::thread writer([&] {
        sink.write(testFrame(0));
        sink.write(testFrame(1));
    });
    bool second = false;
    for (int i = 0; i < 1000 && !second; ++i) {
        second = fs::exists(work / "frame_000001.png");
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    EXPECT_TRUE(second) << "frame 1 was not written while frame 0 waited";
    EXPECT_EQ(sink.framesWritten(), 0u);
    // Frame 0's encoding goes on once its bytes are read.
    std::string bytes;
    {
        const int fd = ::open(fifo.c_str(), O_RDONLY);
        ASSERT_GE(fd, 0);
        char buffer[4096];
        for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;)
            bytes.append(buffer, static_cast<std::size_t>(n));
        ::close(fd);
    }
    writer.join();
    sink.finish();
    EXPECT_EQ(sink.framesWritten(), 2u);
    const cv::Mat first = cv::imdecode(std::vector<uchar>(bytes.begin(), bytes.end()), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(first.empty());
    EXPECT_EQ(cv::norm(first, testFrame(0), cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(readBack(dir / "frame_000001.png"), testFrame(1), cv::NORM_INF), 0.0);
}

// Frames 0..7 into a sequence whose frame 2 cannot be written (a folder stands where its file
// goes), the encoding of frame 2 held until frames 3 and 4 are written where threads allow (its
// temporary file a FIFO read only then); returns what the first error said, counting the calls
// that threw.
struct FailedRun {
    int thrown = 0;
    std::size_t writtenAtFirstError = 0;
};
FailedRun writeAroundAFailure(FrameSink& sink, const fs::path& work, bool sideBySide)
{
    fs::create_directories(work / "frame_000002.png");
    const fs::path fifo = work / ".frame_000002.partial.png";
    EXPECT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    std::thread reader([&] {
        for (int i = 0; sideBySide && i < 1000; ++i) {
            if (fs::exists(work / "frame_000003.png") && fs::exists(work / "frame_000004.png"))
                break;
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        const int fd = ::open(fifo.c_str(), O_RDONLY);
        char buffer[4096];
        while (fd >= 0 && ::read(fd, buffer, sizeof buffer) > 0) {
        }
        ::close(fd);
    });
    FailedRun run;
    for (int k = 0; k < 8; ++k) {
        try {
            sink.write(testFrame(k));
        } catch (const SinkError&) {
            if (run.thrown++ == 0)
                run.writtenAtFirstError = sink.framesWritten();
        }
    }
    try {
        sink.finish();
    } catch (const SinkError&) {
        if (run.thrown++ == 0)
            run.writtenAtFirstError = sink.framesWritten();
    }
    reader.join(); // frame 2 was encoded before finish() returned
    if (sideBySide) {
        EXPECT_TRUE(fs::exists(work / "frame_000004.png")) << "frames 3 and 4 not written while frame 2 waited";
    }
    return run;
}

// Defects caught: frames written after a failed one (by other threads) counted as written, kept
// in the partial output or listed there (a gap a reader cannot see), the output finalised after
// a failed write, and a BackgroundSink naming a later frame than the one whose write failed
// (counting the frames it handed on, not those written). One thread and three alike.
TEST(ImageSequenceSink, AFailedWriteCountsTheFramesBeforeItAndKeepsNoneAfter)
{
    const fs::path base = test::scratchDir("Sink_sequence_failed");
    for (const std::size_t threads : {1u, 3u}) {
        for (const bool background : {false, true}) {
            SCOPED_TRACE(fmt::format("{} threads{}", threads, background ? ", behind a BackgroundSink" : ""));
            const fs::path dir = base / fmt::format("out{}{}", threads, background ? "b" : "");
            auto sequence = std::make_unique<ImageSequenceSink>(dir, false, 30.0, threads);
            std::unique_ptr<FrameSink> sink = std::move(sequence);
            BackgroundSink* behind = nullptr;
            if (background) {
                auto wrapped = std::make_unique<BackgroundSink>(std::move(sink), 2);
                behind = wrapped.get();
                sink = std::move(wrapped);
            }
            const FailedRun run = writeAroundAFailure(*sink, temporaryPath(dir, true), threads > 1);
            EXPECT_GE(run.thrown, 1);
            if (!background) {
                EXPECT_EQ(run.writtenAtFirstError, 2u);
            } else {
                EXPECT_EQ(behind->failedFrame(), std::optional<std::size_t>(2));
            }
            EXPECT_EQ(sink->framesWritten(), 2u);
            EXPECT_FALSE(fs::exists(dir)) << "a failed run's output under its final name";
            const fs::path kept = sink->abandon(true);
            ASSERT_EQ(kept, partialPath(dir, true));
            std::vector<std::string> files;
            for (const auto& [name, bytes] : filesUnder(kept))
                files.push_back(name);
            EXPECT_EQ(files, (std::vector<std::string>{"frame_000000.png", "frame_000001.png", "rgb.txt"}));
            std::ifstream list(kept / "rgb.txt");
            const std::string text{std::istreambuf_iterator<char>(list), {}};
            EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 3 + 2) << text; // header and two frames
        }
    }
}

} // namespace
} // namespace defocus
