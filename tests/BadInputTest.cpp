// SPDX-License-Identifier: LGPL-2.1-or-later
// Bad input from disk: every broken file, list or folder gives one message that
// names the file (and line or frame), through the library and through the defocus binary, and
// leaves no output behind. The cases that need frames rendered before the failure are in
// BadInputGLTest.cpp.
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "sources/FrameSource.hpp"
#include "sources/ImageHeader.hpp"
#include "sources/ImageIO.hpp"
#include "sources/TumLists.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

void writeImage(const fs::path& file, const cv::Mat& image)
{
    enableOpenExr();
    fs::create_directories(file.parent_path());
    ASSERT_TRUE(cv::imwrite(file.string(), image)) << file;
}

std::vector<char> bytesOf(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const fs::path& file, const std::vector<char>& bytes, std::size_t count)
{
    std::ofstream(file, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(count));
}

void writeText(const fs::path& file, const std::string& text)
{
    std::ofstream(file, std::ios::binary) << text;
}

// A frame with structure, so that a truncated file cannot hide in a flat region.
cv::Mat colourFrame(cv::Size size = {64, 48})
{
    cv::Mat frame(size, CV_8UC3);
    cv::randu(frame, 0, 255);
    return frame;
}

cv::Mat depthFrame(cv::Size size = {64, 48})
{
    cv::Mat depth(size, CV_16UC1);
    cv::randu(depth, 500, 5000);
    return depth;
}

std::string errorOf(const std::function<void()>& call)
{
    try {
        call();
    } catch (const SourceError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no SourceError thrown";
    return {};
}

std::vector<Frame> readAll(FrameSource& source)
{
    std::vector<Frame> frames;
    while (std::optional<Frame> frame = source.next())
        frames.push_back(std::move(*frame));
    return frames;
}

std::vector<std::string> fileNames(const fs::path& dir)
{
    std::vector<std::string> names;
    std::error_code ec;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

#define EXPECT_CONTAINS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

// ---- Images ------------------------------------------------------------------------------------

TEST(BadImage, TruncatedPngNamesFileAndWhereItEnds)
{
    const fs::path dir = test::scratchDir("Bad_png_truncated");
    writeImage(dir / "whole.png", colourFrame());
    const std::vector<char> bytes = bytesOf(dir / "whole.png");
    writeBytes(dir / "cut.png", bytes, bytes.size() / 2);
    const std::string message = errorOf([&] { readColor(dir / "cut.png"); });
    EXPECT_CONTAINS(message, "cannot read colour image '" + (dir / "cut.png").string() + "'");
    EXPECT_CONTAINS(message, "truncated PNG");
    EXPECT_CONTAINS(message, fmt::format("ends at byte {}", bytes.size() / 2));

    // Cut just before IEND: every pixel is there, but the file is still incomplete.
    writeBytes(dir / "no_iend.png", bytes, bytes.size() - 12);
    EXPECT_CONTAINS(errorOf([&] { readColor(dir / "no_iend.png"); }), "truncated PNG");
}

TEST(BadImage, CorruptPngDataNamesTheFile)
{
    const fs::path dir = test::scratchDir("Bad_png_corrupt");
    writeImage(dir / "depth.png", depthFrame());
    std::vector<char> bytes = bytesOf(dir / "depth.png");
    // Scramble the compressed pixels of IDAT; its CRC no longer matches.
    const std::size_t idat = std::string_view(bytes.data(), bytes.size()).find("IDAT");
    ASSERT_NE(idat, std::string_view::npos);
    for (std::size_t i = idat + 8; i < idat + 40; ++i)
        bytes[i] = static_cast<char>(bytes[i] ^ 0x5a);
    writeBytes(dir / "depth.png", bytes, bytes.size());
    const std::string message = errorOf([&] { readDepth(dir / "depth.png", 1000.0); });
    EXPECT_CONTAINS(message, "cannot read depth image '" + (dir / "depth.png").string() + "'");
    EXPECT_CONTAINS(message, "PNG decoder failed");
}

TEST(BadImage, TruncatedExrNamesTheMissingChunk)
{
    const fs::path dir = test::scratchDir("Bad_exr_truncated");
    cv::Mat metres(48, 64, CV_32FC1);
    cv::randu(metres, 0.5f, 8.0f);
    writeImage(dir / "whole.exr", metres);
    ASSERT_EQ(readDepth(dir / "whole.exr", 1000.0).size(), metres.size());
    const std::vector<char> bytes = bytesOf(dir / "whole.exr");
    writeBytes(dir / "cut.exr", bytes, bytes.size() * 2 / 3);
    const std::string message = errorOf([&] { readDepth(dir / "cut.exr", 1000.0); });
    EXPECT_CONTAINS(message, "cannot read depth image '" + (dir / "cut.exr").string() + "'");
    EXPECT_CONTAINS(message, "truncated OpenEXR");
    EXPECT_CONTAINS(message, "scan-line chunk");

    // Cut inside the header.
    writeBytes(dir / "header.exr", bytes, 40);
    EXPECT_CONTAINS(errorOf([&] { readColor(dir / "header.exr"); }), "truncated OpenEXR");
}

// OpenEXR reads a value of a type it knows by its content, not by the size the header gives it,
// and goes on from where the content ends. Defect caught: the header check skipping such a
// value by its size, so that where the two disagree the check and the decoder walk on from
// different bytes and may size the image from different dataWindows (a fuzzed file: 8x65542 by
// the check, 8x6 decoded), which the check's pixel limit then does not hold for.
TEST(BadImage, ExrValueOfAnotherSizeThanItsTypeIsRefusedNamingTheAttribute)
{
    const fs::path dir = test::scratchDir("Bad_exr_value_size");
    writeImage(dir / "whole.exr", cv::Mat(6, 8, CV_32FC1, cv::Scalar(2.0f)));
    const std::vector<char> bytes = bytesOf(dir / "whole.exr");
    const std::string_view text(bytes.data(), bytes.size());
    ASSERT_EQ(readDepth(dir / "whole.exr", 1000.0).size(), cv::Size(8, 6));
    // The size field of an attribute: after its name, NUL, type, NUL.
    const auto sizeField = [&](std::string_view nameAndType) {
        const std::size_t at = text.find(nameAndType);
        EXPECT_NE(at, std::string_view::npos) << nameAndType;
        return at + nameAndType.size();
    };
    const auto withSize = [&](std::size_t field, std::uint32_t size) {
        std::vector<char> out = bytes;
        for (int i = 0; i < 4; ++i)
            out[field + static_cast<std::size_t>(i)] = static_cast<char>(size >> (8 * i) & 0xff);
        return out;
    };
    // A channel list one byte shorter than its names and their 16 bytes each.
    const std::size_t channels = sizeField(std::string_view("channels\0chlist\0", 16));
    const std::uint32_t listed = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[channels])) |
                                 static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[channels + 1])) << 8;
    std::vector<char> shortList = withSize(channels, listed - 1);
    writeBytes(dir / "chlist.exr", shortList, shortList.size());
    const std::string chlist = errorOf([&] { readDepth(dir / "chlist.exr", 1000.0); });
    EXPECT_CONTAINS(chlist, (dir / "chlist.exr").string());
    EXPECT_CONTAINS(chlist, fmt::format("attribute 'channels' of type 'chlist' holds {} bytes, its size says {}",
                                        listed, listed - 1));
    // A box2i of 20 bytes.
    std::vector<char> wideBox = withSize(sizeField(std::string_view("displayWindow\0box2i\0", 20)), 20);
    writeBytes(dir / "box.exr", wideBox, wideBox.size());
    EXPECT_CONTAINS(errorOf([&] { readColor(dir / "box.exr"); }),
                    "attribute 'displayWindow' of type 'box2i' holds 16 bytes, its size says 20");
}

TEST(BadImage, TruncatedJpegIsAnErrorNotGreyPadding)
{
    const fs::path dir = test::scratchDir("Bad_jpeg_truncated");
    writeImage(dir / "whole.jpg", colourFrame({320, 240}));
    ASSERT_FALSE(readColor(dir / "whole.jpg").empty());
    const std::vector<char> bytes = bytesOf(dir / "whole.jpg");
    writeBytes(dir / "cut.jpg", bytes, bytes.size() * 3 / 4);
    const std::string message = errorOf([&] { readColor(dir / "cut.jpg"); });
    EXPECT_CONTAINS(message, (dir / "cut.jpg").string());
    EXPECT_CONTAINS(message, "truncated JPEG");
}

TEST(BadImage, EmptyUnknownAndMislabelledFiles)
{
    const fs::path dir = test::scratchDir("Bad_formats");
    writeText(dir / "empty.png", "");
    EXPECT_CONTAINS(errorOf([&] { readColor(dir / "empty.png"); }), "the file is empty");

    // A format OpenCV reads but defocus refuses.
    writeImage(dir / "frame.ppm", colourFrame());
    const std::string ppm = errorOf([&] { readColor(dir / "frame.ppm"); });
    EXPECT_CONTAINS(ppm, (dir / "frame.ppm").string());
    EXPECT_CONTAINS(ppm, "not a PNG, JPEG, TIFF, BMP, WebP or OpenEXR image");

    // Recognised by content, not by name: a JPEG called .png reads fine.
    writeImage(dir / "photo.jpg", colourFrame());
    fs::rename(dir / "photo.jpg", dir / "photo.png");
    EXPECT_EQ(readColor(dir / "photo.png").size(), cv::Size(64, 48));
}

// A PNG of 13 header bytes that claims 100000 x 100000 pixels (30 GB as 8-bit RGB) is refused
// from its header, before libpng allocates anything.
TEST(BadImage, AbsurdSizeIsRefusedBeforeDecoding)
{
    const fs::path file = test::scratchDir("Bad_huge") / "huge.png";
    const std::vector<unsigned char> png = {
        0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n',                         // signature
        0, 0, 0, 13, 'I', 'H', 'D', 'R', 0, 1, 0x86, 0xa0, 0, 1, 0x86, 0xa0, // 100000 x 100000
        8, 2, 0, 0, 0, 0, 0, 0, 0,                                           // 8-bit RGB, CRC
        0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
    writeBytes(file, std::vector<char>(png.begin(), png.end()), png.size());
    const std::string message = errorOf([&] { readColor(file); });
    EXPECT_CONTAINS(message, file.string());
    EXPECT_CONTAINS(message, "100000x100000 pixels, more than the 134217728 allowed");

    const ImageHeader header = readImageHeader(png);
    EXPECT_EQ(header.format, ImageFormat::Png);
    EXPECT_EQ(header.width, 100000u);
    EXPECT_TRUE(header.problem.empty()) << header.problem;
}

TEST(BadImage, WrongBitDepthOrChannelCountNamesTheSampleFormat)
{
    const fs::path dir = test::scratchDir("Bad_samples");
    writeImage(dir / "depth_rgba16.png", cv::Mat(4, 4, CV_16UC4, cv::Scalar::all(1000)));
    const std::string rgba = errorOf([&] { readDepth(dir / "depth_rgba16.png", 1000.0); });
    EXPECT_CONTAINS(rgba, (dir / "depth_rgba16.png").string());
    EXPECT_CONTAINS(rgba, "16-bit unsigned with 4 channels");

    writeImage(dir / "depth_grey8.jpg", cv::Mat(4, 4, CV_8UC1, cv::Scalar(90)));
    EXPECT_CONTAINS(errorOf([&] { readDepth(dir / "depth_grey8.jpg", 1000.0); }), "8-bit unsigned with 1 channel");
}

// ---- Colour and depth sizes --------------------------------------------------------------------

TEST(BadPair, DepthOfAnotherSizeButTheSameAspectIsAccepted)
{
    const fs::path dir = test::scratchDir("Bad_size_ok");
    writeImage(dir / "colour.png", colourFrame({640, 480}));
    writeImage(dir / "half.png", depthFrame({320, 240}));
    writeImage(dir / "odd.png", depthFrame({321, 240})); // within one pixel of 4:3
    for (const char* depth : {"half.png", "odd.png"}) {
        const std::unique_ptr<FrameSource> source = openSource({dir / "colour.png", dir / depth, {}});
        const std::optional<Frame> frame = source->next();
        ASSERT_TRUE(frame.has_value()) << depth;
        EXPECT_EQ(frame->color.size(), cv::Size(640, 480));
    }
}

TEST(BadPair, DepthOfAnotherAspectRatioNamesBothFilesAndSizes)
{
    const fs::path dir = test::scratchDir("Bad_size_aspect");
    writeImage(dir / "colour.png", colourFrame({64, 48}));
    writeImage(dir / "square.png", depthFrame({48, 48}));
    const std::string message = errorOf([&] { openSource({dir / "colour.png", dir / "square.png", {}}); });
    EXPECT_CONTAINS(message, "depth '" + (dir / "square.png").string() + "' is 48x48");
    EXPECT_CONTAINS(message, "colour '" + (dir / "colour.png").string() + "' is 64x48");
    EXPECT_CONTAINS(message, "aspect ratios (1.000 and 1.333) differ");
}

TEST(BadPair, FolderFrameOfAnotherAspectFailsAtThatFrame)
{
    const fs::path dir = test::scratchDir("Bad_size_folder");
    for (int k = 0; k < 3; ++k) {
        writeImage(dir / "rgb" / fmt::format("{}.png", k), colourFrame());
        writeImage(dir / "depth" / fmt::format("{}.png", k), depthFrame(k == 2 ? cv::Size(48, 64) : cv::Size(32, 24)));
    }
    const std::unique_ptr<FrameSource> source = openSource({dir / "rgb", dir / "depth", {}});
    EXPECT_TRUE(source->next().has_value());
    EXPECT_TRUE(source->next().has_value());
    const std::string message = errorOf([&] { source->next(); });
    EXPECT_CONTAINS(message, (dir / "depth" / "2.png").string() + "' is 48x64");
    EXPECT_CONTAINS(message, (dir / "rgb" / "2.png").string() + "' is 64x48");
}

// ---- Counts, folders and lists -----------------------------------------------------------------

TEST(BadFolder, EmptyDepthFolderAndVanishedFrame)
{
    const fs::path dir = test::scratchDir("Bad_folders");
    for (int k = 0; k < 2; ++k)
        writeImage(dir / "rgb" / fmt::format("{}.png", k), colourFrame());
    fs::create_directories(dir / "depth");
    const std::string empty = errorOf([&] { openSource({dir / "rgb", dir / "depth", {}}); });
    EXPECT_CONTAINS(empty, (dir / "depth").string() + "' holds 0");

    // A file that disappears between listing and reading fails at its frame, by name.
    const std::unique_ptr<FrameSource> source = openSource({dir / "rgb", {}, {}});
    fs::remove(dir / "rgb" / "1.png");
    EXPECT_TRUE(source->next().has_value());
    const std::string gone = errorOf([&] { source->next(); });
    EXPECT_CONTAINS(gone, (dir / "rgb" / "1.png").string() + "': file does not exist");
}

TEST(BadList, GarbageLinesNameListAndLine)
{
    const fs::path list = "seq/associations.txt";
    const auto parse = [&](const std::string& text) {
        std::istringstream in(text);
        return errorOf([&] { tum::parseAssociations(in, list); });
    };
    const std::string good = "1.0 rgb/1.png 1.01 depth/1.png\n";
    EXPECT_CONTAINS(parse(good + "nan rgb/2.png 2.0 depth/2.png\n"), "seq/associations.txt:2: expected");
    EXPECT_CONTAINS(parse(good + "# comment\n\n2.0 rgb/2.png 2.0 depth/2.png extra\n"), "associations.txt:4:");
    EXPECT_CONTAINS(parse(good + "1e999 rgb/2.png 2.0 depth/2.png\n"), "associations.txt:2:");
    EXPECT_CONTAINS(parse(good + "2.0 rgb/2.png 0x1p3 depth/2.png\n"), "associations.txt:2:");
    // Binary junk is shown as '?', so the message stays one printable line.
    const std::string binary = parse(good + good + std::string("\x01\x02garbage\x7f 1 2 3\n"));
    EXPECT_CONTAINS(binary, "associations.txt:3: expected 'timestamp file timestamp file', got '??garbage? 1 2 3'");

    std::istringstream rgb("1.0 rgb/1.png\r\n1.5\n");
    EXPECT_CONTAINS(errorOf([&] { tum::parseTimestampList(rgb, "rgb.txt"); }),
                    "rgb.txt:2: expected 'timestamp file', got '1.5'");
}

TEST(BadList, TumFolderWithAnEmptyListOrAListedFolder)
{
    const fs::path dir = test::scratchDir("Bad_tum");
    writeText(dir / "rgb.txt", "# color images\n");
    writeText(dir / "depth.txt", "# depth maps\n");
    EXPECT_CONTAINS(errorOf([&] { openSource({dir, {}, {}}); }), "rgb.txt lists no frames");

    fs::create_directories(dir / "rgb" / "1.png"); // a folder where an image is listed
    writeImage(dir / "depth" / "1.png", depthFrame());
    writeText(dir / "associations.txt", "1.0 rgb/1.png 1.0 depth/1.png\n");
    const std::string message = errorOf([&] { openSource({dir, {}, {}}); });
    EXPECT_CONTAINS(message, "associations.txt:1: listed file '" + (dir / "rgb" / "1.png").string() +
                                 "' is not a regular file");
}

TEST(BadList, FrameRateOfAbsurdTimestampsFallsBackTo30Hz)
{
    EXPECT_EQ(tum::estimateFrameRate({0.0, 1e-9, 2e-9}), 30.0);  // a gigahertz camera
    EXPECT_EQ(tum::estimateFrameRate({0.0, 1e300, -1e300}), 30.0); // intervals of 1e300 s
    EXPECT_NEAR(tum::estimateFrameRate({0.0, 0.04, 0.08, 0.2}), 25.0, 1e-9); // one dropped frame
}

// ---- Video -------------------------------------------------------------------------------------

fs::path writeVideo(const fs::path& file, int frames)
{
    cv::VideoWriter writer(file.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), 25.0,
                           cv::Size(64, 48));
    EXPECT_TRUE(writer.isOpened()) << file;
    for (int k = 0; k < frames; ++k)
        writer.write(colourFrame());
    return file;
}

TEST(BadVideo, TruncatedMp4DoesNotOpenAndNamesTheFile)
{
    const fs::path dir = test::scratchDir("Bad_video_mp4");
    const std::vector<char> bytes = bytesOf(writeVideo(dir / "whole.mp4", 10));
    writeBytes(dir / "cut.mp4", bytes, bytes.size() * 6 / 10); // the index (moov) is at the end
    const std::string message = errorOf([&] { openSource({dir / "cut.mp4", {}, {}}); });
    EXPECT_CONTAINS(message, "cannot open video '" + (dir / "cut.mp4").string() + "'");
}

TEST(BadVideo, TruncatedMkvEndsEarlyWithAWarningNamingBothCounts)
{
    const fs::path dir = test::scratchDir("Bad_video_mkv");
    const std::vector<char> bytes = bytesOf(writeVideo(dir / "whole.mkv", 10));
    writeBytes(dir / "cut.mkv", bytes, bytes.size() * 6 / 10);
    const std::unique_ptr<FrameSource> source = openSource({dir / "cut.mkv", {}, {}});
    ASSERT_EQ(source->frameCount(), std::optional<std::size_t>(10));
    test::LogCapture log;
    const std::vector<Frame> frames = readAll(*source);
    EXPECT_LT(frames.size(), 10u);
    EXPECT_CONTAINS(log.text(), fmt::format("video '{}': decoding stopped after {} of the 10 frames",
                                            (dir / "cut.mkv").string(), frames.size()));
}

// ---- The defocus binary ------------------------------------------------------------------------

using test::CliResult;
using test::runDefocus;

std::string quoted(const fs::path& path)
{
    return fmt::format("'{}'", path.string());
}

TEST(BadInputCli, MissingInputExitsNonZeroAndWritesNothing)
{
    const fs::path dir = test::scratchDir("Cli_missing");
    const CliResult r = runDefocus(quoted(dir / "nothing.png") + " -o " + quoted(dir / "out" / "clip.mp4"));
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_CONTAINS(r.output, "input '" + (dir / "nothing.png").string() + "' does not exist");
    EXPECT_FALSE(fs::exists(dir / "out")) << r.output;
}

TEST(BadInputCli, GarbageAssociationLineNamesFileAndLine)
{
    const fs::path dir = test::scratchDir("Cli_garbage_list");
    writeImage(dir / "tum" / "rgb" / "1.png", colourFrame());
    writeImage(dir / "tum" / "depth" / "1.png", depthFrame());
    writeText(dir / "tum" / "associations.txt", "# pairs\n1.0 rgb/1.png 1.0 depth/1.png\n1.1 rgb/1.png\n");
    const CliResult r = runDefocus(quoted(dir / "tum") + " -o " + quoted(dir / "out/"));
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_CONTAINS(r.output, (dir / "tum" / "associations.txt").string() + ":3: expected");
    EXPECT_FALSE(fs::exists(dir / "out")) << r.output;
}

TEST(BadInputCli, UnequalCountsNameBothFolders)
{
    const fs::path dir = test::scratchDir("Cli_counts");
    for (int k = 0; k < 3; ++k)
        writeImage(dir / "rgb" / fmt::format("{}.png", k), colourFrame());
    writeImage(dir / "depth" / "0.png", depthFrame());
    const CliResult r = runDefocus(quoted(dir / "rgb") + " --depth " + quoted(dir / "depth") + " -o " +
                                   quoted(dir / "out.mp4"));
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_CONTAINS(r.output, "holds 3 images but depth folder '" + (dir / "depth").string() + "' holds 1");
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"depth", "rgb"})) << r.output;
}

TEST(BadInputCli, CorruptImageAndMismatchedDepthFailBeforeAnyOutput)
{
    const fs::path dir = test::scratchDir("Cli_single");
    writeImage(dir / "photo.png", colourFrame());
    writeImage(dir / "square.png", depthFrame({48, 48}));
    CliResult r = runDefocus(quoted(dir / "photo.png") + " --depth " + quoted(dir / "square.png") + " -o " +
                             quoted(dir / "out.png"));
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_CONTAINS(r.output, "depth '" + (dir / "square.png").string() + "' is 48x48 but colour '" +
                                  (dir / "photo.png").string() + "' is 64x48");

    const std::vector<char> bytes = bytesOf(dir / "photo.png");
    writeBytes(dir / "photo.png", bytes, bytes.size() / 3);
    r = runDefocus(quoted(dir / "photo.png") + " -o " + quoted(dir / "out.png"));
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_CONTAINS(r.output, "cannot read colour image '" + (dir / "photo.png").string() + "': truncated PNG");
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"photo.png", "square.png"})) << r.output;
}

// ---- Requests the clip cannot meet: refused before any frame (and before GL), nothing written ----

/// A folder pair of three 64x48 frames: dir/rgb and dir/depth.
fs::path threeFrames(const std::string& name)
{
    const fs::path dir = test::scratchDir(name);
    for (int k = 0; k < 3; ++k) {
        writeImage(dir / "rgb" / fmt::format("{}.png", k), colourFrame());
        writeImage(dir / "depth" / fmt::format("{}.png", k), depthFrame());
    }
    return dir;
}

std::string clipOf(const fs::path& dir)
{
    return quoted(dir / "rgb") + " --depth " + quoted(dir / "depth");
}

/// Lines of `text` that hold "error".
long errorLines(const std::string& text)
{
    std::istringstream lines(text);
    long count = 0;
    for (std::string line; std::getline(lines, line);)
        count += line.find("error") != std::string::npos;
    return count;
}

// Defect: a one-image output (-o x.png, x.exr) of a clip of several frames rendered every frame and
// kept the last without a word. Refused in one line that says what to do instead.
TEST(BadRequestCli, OneImageOutputOfSeveralFramesIsRefused)
{
    const fs::path dir = threeFrames("Cli_one_image");
    for (const std::string name : {"out.png", "out.exr"}) {
        const CliResult r = runDefocus(clipOf(dir) + " -o " + quoted(dir / name));
        EXPECT_EQ(r.exitCode, 1) << r.output;
        EXPECT_EQ(errorLines(r.output), 1) << r.output;
        EXPECT_CONTAINS(r.output, "-o '" + (dir / name).string() + "' holds one image but '" + (dir / "rgb").string() +
                                      "' gives 3 frames: write them to a folder");
        EXPECT_CONTAINS(r.output, "--start N --frames 1");
    }
    const CliResult every = runDefocus(clipOf(dir) + " --every 2 -o " + quoted(dir / "out.png"));
    EXPECT_CONTAINS(every.output, "gives 2 frames"); // frames 0 and 2
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"depth", "rgb"})) << every.output;
}

// Defect: --contact-frame beyond the clip (or one --every skips) warned and exited 0 without the
// sheet, after rendering the whole clip.
TEST(BadRequestCli, ContactFrameTheClipNeverGivesIsRefused)
{
    const fs::path dir = threeFrames("Cli_contact_frame");
    const std::string sheet = " --contact-sheet " + quoted(dir / "sheet.png");
    CliResult r = runDefocus(clipOf(dir) + " -o " + quoted(dir / "out/") + sheet + " --contact-frame 5");
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_EQ(errorLines(r.output), 1) << r.output;
    EXPECT_CONTAINS(r.output, "--contact-frame 5 is beyond the 3 frames of '" + (dir / "rgb").string() + "' (0 to 2)");
    r = runDefocus(clipOf(dir) + " -o " + quoted(dir / "out/") + sheet + " --contact-frame 1 --every 2");
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_CONTAINS(r.output, "--contact-frame 1 is not among the frames --start 0 --every 2 take (0, 2, ...)");
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"depth", "rgb"})) << r.output;
}

// Defect: a typo in an output's folder created the whole missing path (-o /nonexistent/dir/x.mp4
// made /nonexistent/dir/). Only the last folder of a folder output is made.
TEST(BadRequestCli, MissingOutputFolderIsAnErrorNotATree)
{
    const fs::path dir = threeFrames("Cli_missing_folder");
    const fs::path missing = dir / "typo" / "deeper";
    for (const std::string& output : {(missing / "x.mp4").string(), (missing / "x.png").string(), missing.string() + "/"}) {
        const CliResult r = runDefocus(clipOf(dir) + " --frames 1 -o " + quoted(fs::path(output)));
        EXPECT_EQ(r.exitCode, 1) << r.output;
        EXPECT_EQ(errorLines(r.output), 1) << r.output;
        const fs::path folder = output.back() == '/' ? dir / "typo" : missing;
        EXPECT_CONTAINS(r.output, "cannot write '" + output + "': folder '" + folder.string() + "' does not exist");
    }
    const CliResult sheet = runDefocus(clipOf(dir) + " -o " + quoted(dir / "out/") + " --contact-sheet " +
                                       quoted(missing / "sheet.png"));
    EXPECT_EQ(sheet.exitCode, 1) << sheet.output;
    EXPECT_CONTAINS(sheet.output, "folder '" + missing.string() + "' does not exist");
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"depth", "rgb"})) << sheet.output;
}

// Defect: -o or INPUT beside --batch (whose manifest names them), and --shard, --redo,
// --report-dir or --in-flight without it, silently ignored.
TEST(BadRequestCli, OptionsThatWouldBeIgnoredBesideOrWithoutBatchAreRefused)
{
    const fs::path dir = threeFrames("Cli_batch_options");
    const std::string manifest = quoted(dir / "clips.tsv");
    for (const std::string& arguments :
         {"--batch " + manifest + " -o " + quoted(dir / "x.mp4"), "--batch " + manifest + " " + clipOf(dir),
          "--batch " + manifest + " --report " + quoted(dir / "r.json")}) {
        const CliResult r = runDefocus(arguments);
        EXPECT_EQ(r.exitCode, 2) << arguments << "\n" << r.output;
        EXPECT_EQ(errorLines(r.output), 1) << r.output;
        EXPECT_CONTAINS(r.output, "does not go with --batch");
    }
    for (const std::string& option : {std::string("--shard 0/2"), std::string("--redo"), "--report-dir " + quoted(dir), std::string("--in-flight 2")}) {
        const CliResult r = runDefocus(clipOf(dir) + " -o " + quoted(dir / "out/") + " " + option);
        EXPECT_EQ(r.exitCode, 2) << option << "\n" << r.output;
        EXPECT_CONTAINS(r.output, option.substr(0, option.find(' ')) + " is an option of --batch MANIFEST");
    }
    EXPECT_EQ(fileNames(dir), (std::vector<std::string>{"depth", "rgb"}));
}

} // namespace
} // namespace defocus
