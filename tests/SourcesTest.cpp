// SPDX-License-Identifier: LGPL-2.1-or-later
// Frame sources: TUM pairing (associations and timestamps), folder pairs, single images, video
// files, and the errors for bad inputs.
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "sources/FrameSource.hpp"
#include "sources/ImageIO.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

const fs::path tumDir = test::dataDir() / "tum_fr1_rpy";

void writeImage(const fs::path& file, const cv::Mat& image)
{
    fs::create_directories(file.parent_path());
    ASSERT_TRUE(cv::imwrite(file.string(), image)) << file;
}

void writeText(const fs::path& file, const std::string& text)
{
    std::ofstream(file) << text;
}

std::vector<Frame> readAll(FrameSource& source)
{
    std::vector<Frame> frames;
    while (std::optional<Frame> frame = source.next())
        frames.push_back(std::move(*frame));
    return frames;
}

std::string openError(const SourceOptions& options)
{
    try {
        openSource(options);
    } catch (const SourceError& e) {
        return e.what();
    }
    ADD_FAILURE() << "openSource(" << options.input << ") did not throw SourceError";
    return {};
}

/// "t_rgb rgb/x.png t_depth depth/y.png" lines of the bundled associations.txt.
struct Association {
    double rgbTime;
    std::string rgb;
    std::string depth;
};

std::vector<Association> bundledAssociations()
{
    std::vector<Association> out;
    std::ifstream in(tumDir / "associations.txt");
    for (std::string line; std::getline(in, line);) {
        std::istringstream words(line);
        Association a{};
        double depthTime = 0.0;
        if (words >> a.rgbTime >> a.rgb >> depthTime >> a.depth)
            out.push_back(a);
    }
    return out;
}

// A TUM folder of six 4x4 frames. Colour frame k is filled with 10*k; its depth with k+1 units of
// 1000 (0.2*(k+1) m at TUM's scale of 5000). Depth timestamps are off by up to 16 ms, frame 1's
// own depth is 12 ms away while frame 0's is 17.3 ms away (so "first within 20 ms" would pick the
// wrong one), and frame 3 has no depth within 20 ms. depth.txt is not in time order.
constexpr double frameStep = 0.0333;
constexpr int syntheticFrames = 6;
constexpr int frameWithoutDepth = 3;

double rgbTime(int k)
{
    return 1000.0 + k * frameStep;
}

fs::path makeSyntheticTum(const std::string& name)
{
    const fs::path dir = test::scratchDir(name);
    const double depthOffset[syntheticFrames] = {+0.016, -0.012, -0.016, 0.0, +0.010, 0.0};
    std::string rgbList = "# color images\n# file: 'synthetic'\n# timestamp filename\n";
    std::vector<std::string> depthLines;
    for (int k = 0; k < syntheticFrames; ++k) {
        const std::string rgb = fmt::format("rgb/{:.6f}.png", rgbTime(k));
        writeImage(dir / rgb, cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(10.0 * k)));
        rgbList += fmt::format("{:.6f} {}\n", rgbTime(k), rgb);
        if (k == frameWithoutDepth)
            continue;
        const double t = rgbTime(k) + depthOffset[k];
        const std::string depth = fmt::format("depth/{:.6f}.png", t);
        writeImage(dir / depth, cv::Mat(4, 4, CV_16UC1, cv::Scalar(1000.0 * (k + 1))));
        depthLines.push_back(fmt::format("{:.6f} {}\n", t, depth));
    }
    std::swap(depthLines[1], depthLines[3]);
    std::string depthList = "# depth maps\n# file: 'synthetic'\n# timestamp filename\n";
    for (const std::string& line : depthLines)
        depthList += line;
    writeText(dir / "rgb.txt", rgbList);
    writeText(dir / "depth.txt", depthList);
    return dir;
}

TEST(TumSource, BundledSequenceGivesAllTenPairsFromAssociations)
{
    const std::unique_ptr<FrameSource> source = openSource({tumDir, std::nullopt, std::nullopt});
    EXPECT_EQ(source->frameCount(), std::optional<std::size_t>(10));
    EXPECT_NEAR(source->frameRate(), 30.0, 1.0);
    EXPECT_NE(source->describe().find("associations.txt"), std::string::npos);

    const std::vector<Association> expected = bundledAssociations();
    ASSERT_EQ(expected.size(), 10u);
    const std::vector<Frame> frames = readAll(*source);
    ASSERT_EQ(frames.size(), 10u);
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const Frame& f = frames[i];
        EXPECT_EQ(f.index, i);
        EXPECT_EQ(f.name, expected[i].rgb);
        EXPECT_DOUBLE_EQ(f.timestampS, expected[i].rgbTime);
        ASSERT_EQ(f.color.type(), CV_8UC3);
        EXPECT_EQ(f.color.size(), cv::Size(640, 480));
        ASSERT_EQ(f.depth.type(), CV_32FC1) << f.name;
        EXPECT_EQ(f.depth.size(), cv::Size(640, 480));
        // TUM's scale of 5000 units per metre: the office is within a few metres.
        double hi = 0.0;
        cv::minMaxLoc(f.depth, nullptr, &hi);
        EXPECT_GT(hi, 0.5);
        EXPECT_LT(hi, 10.0);
        const cv::Mat expectedDepth = readDepth(tumDir / expected[i].depth, 5000.0);
        EXPECT_EQ(cv::norm(f.depth, expectedDepth, cv::NORM_INF), 0.0) << f.name;
    }
    EXPECT_FALSE(source->next().has_value());
}

TEST(TumSource, BundledSequenceByTimestampFindsTheSamePairs)
{
    // The same lists without associations.txt: images linked, not copied.
    const fs::path dir = test::scratchDir("Tum_bundled_by_time");
    fs::create_directory_symlink(tumDir / "rgb", dir / "rgb");
    fs::create_directory_symlink(tumDir / "depth", dir / "depth");
    fs::copy_file(tumDir / "rgb.txt", dir / "rgb.txt");
    fs::copy_file(tumDir / "depth.txt", dir / "depth.txt");

    const std::unique_ptr<FrameSource> source = openSource({dir, std::nullopt, std::nullopt});
    EXPECT_NE(source->describe().find("timestamp"), std::string::npos) << source->describe();
    const std::vector<Association> expected = bundledAssociations();
    const std::vector<Frame> frames = readAll(*source);
    ASSERT_EQ(frames.size(), 10u);
    for (std::size_t i = 0; i < frames.size(); ++i) {
        EXPECT_EQ(frames[i].name, expected[i].rgb);
        ASSERT_FALSE(frames[i].depth.empty()) << frames[i].name;
        const cv::Mat expectedDepth = readDepth(tumDir / expected[i].depth, 5000.0);
        EXPECT_EQ(cv::norm(frames[i].depth, expectedDepth, cv::NORM_INF), 0.0) << frames[i].name;
    }
}

TEST(TumSource, PairsEachColourFrameWithTheNearestDepthWithin20ms)
{
    const fs::path dir = makeSyntheticTum("Tum_synthetic");
    const std::unique_ptr<FrameSource> source = openSource({dir, std::nullopt, std::nullopt});
    EXPECT_EQ(source->frameCount(), std::optional<std::size_t>(syntheticFrames));
    EXPECT_NEAR(source->frameRate(), 1.0 / frameStep, 0.1);

    const std::vector<Frame> frames = readAll(*source);
    ASSERT_EQ(frames.size(), static_cast<std::size_t>(syntheticFrames)); // every colour frame out
    for (int k = 0; k < syntheticFrames; ++k) {
        const Frame& f = frames[static_cast<std::size_t>(k)];
        EXPECT_EQ(f.name, fmt::format("rgb/{:.6f}.png", rgbTime(k)));
        EXPECT_NEAR(f.timestampS, rgbTime(k), 1e-9);
        EXPECT_EQ(f.color.at<cv::Vec3b>(0, 0)[0], 10 * k);
        if (k == frameWithoutDepth) {
            EXPECT_TRUE(f.depth.empty()) << f.name;
            continue;
        }
        ASSERT_EQ(f.depth.type(), CV_32FC1) << f.name;
        EXPECT_FLOAT_EQ(f.depth.at<float>(2, 2), 0.2f * static_cast<float>(k + 1)) << f.name;
    }
}

TEST(TumSource, DepthScaleOptionOverridesTheTumDefault)
{
    const fs::path dir = makeSyntheticTum("Tum_scale");
    const std::unique_ptr<FrameSource> source = openSource({dir, std::nullopt, 1000.0});
    const std::optional<Frame> first = source->next();
    ASSERT_TRUE(first.has_value());
    EXPECT_FLOAT_EQ(first->depth.at<float>(0, 0), 1.0f); // 1000 units at 1000 per metre
}

TEST(TumSource, GarbageLineInAssociationsNamesFileAndLine)
{
    const fs::path dir = makeSyntheticTum("Tum_garbage_assoc");
    std::string text;
    for (int k = 0; k < 6; ++k) {
        text += fmt::format("{0:.6f} rgb/{0:.6f}.png {0:.6f} rgb/{0:.6f}.png\n", rgbTime(k));
    }
    text += "1000.000000 rgb/1000.000000.png\n"; // line 7: the depth half is missing
    writeText(dir / "associations.txt", text);
    const std::string message = openError({dir, std::nullopt, std::nullopt});
    EXPECT_NE(message.find("associations.txt:7: expected 'timestamp file timestamp file'"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find((dir / "associations.txt").string()), std::string::npos) << message;
}

TEST(TumSource, GarbageLineInRgbListNamesFileAndLine)
{
    const fs::path dir = makeSyntheticTum("Tum_garbage_rgb");
    std::ifstream in(dir / "rgb.txt");
    std::string text((std::istreambuf_iterator<char>(in)), {});
    in.close();
    text += "12:34:56 rgb/late.png\n"; // line 3 comments + 6 entries + this = line 10
    writeText(dir / "rgb.txt", text);
    const std::string message = openError({dir, std::nullopt, std::nullopt});
    EXPECT_NE(message.find("rgb.txt:10: expected 'timestamp file'"), std::string::npos)
        << message;
}

TEST(TumSource, MissingListedFileFailsAtOpenNamingIt)
{
    const fs::path dir = makeSyntheticTum("Tum_missing");
    fs::remove(dir / fmt::format("rgb/{:.6f}.png", rgbTime(4)));
    const std::string message = openError({dir, std::nullopt, std::nullopt});
    EXPECT_NE(message.find(fmt::format("rgb/{:.6f}.png", rgbTime(4))), std::string::npos)
        << message;
    EXPECT_NE(message.find("rgb.txt:8:"), std::string::npos) << message;
    EXPECT_NE(message.find("does not exist"), std::string::npos) << message;

    // A depth file that is paired but missing fails the same way.
    const fs::path dir2 = makeSyntheticTum("Tum_missing_depth");
    fs::remove_all(dir2 / "depth");
    const std::string depthMessage = openError({dir2, std::nullopt, std::nullopt});
    EXPECT_NE(depthMessage.find("depth.txt:"), std::string::npos) << depthMessage;
}

TEST(TumSource, SeparateDepthOptionIsRejected)
{
    const std::string message = openError({tumDir, tumDir / "depth", std::nullopt});
    EXPECT_NE(message.find("TUM"), std::string::npos) << message;
}

TEST(FolderPairSource, PairsBySortedNameInNaturalOrder)
{
    const fs::path dir = test::scratchDir("FolderPair_sorted");
    // Colour k holds k, depth k holds k metres (16-bit millimetres at the default scale).
    for (int k : {10, 2, 1}) {
        writeImage(dir / "rgb" / fmt::format("img_{}.png", k),
                   cv::Mat(3, 3, CV_8UC3, cv::Scalar::all(k)));
        writeImage(dir / "depth" / fmt::format("d_{}.png", k),
                   cv::Mat(3, 3, CV_16UC1, cv::Scalar(1000.0 * k)));
    }
    writeText(dir / "rgb" / "notes.txt", "not an image");
    const std::unique_ptr<FrameSource> source =
        openSource({dir / "rgb", dir / "depth", std::nullopt});
    EXPECT_EQ(source->frameCount(), std::optional<std::size_t>(3));
    const std::vector<Frame> frames = readAll(*source);
    ASSERT_EQ(frames.size(), 3u);
    const int order[] = {1, 2, 10};
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(frames[i].index, i);
        EXPECT_EQ(frames[i].name, fmt::format("img_{}.png", order[i]));
        EXPECT_EQ(frames[i].color.at<cv::Vec3b>(1, 1)[0], order[i]);
        ASSERT_EQ(frames[i].depth.type(), CV_32FC1);
        EXPECT_FLOAT_EQ(frames[i].depth.at<float>(1, 1), static_cast<float>(order[i]));
    }
}

TEST(FolderPairSource, UnequalCountsNameBothFoldersAndCounts)
{
    const fs::path dir = test::scratchDir("FolderPair_mismatch");
    for (int k = 0; k < 3; ++k)
        writeImage(dir / "colour" / fmt::format("{}.png", k), cv::Mat(2, 2, CV_8UC3));
    for (int k = 0; k < 2; ++k)
        writeImage(dir / "depth" / fmt::format("{}.png", k), cv::Mat(2, 2, CV_16UC1));
    const std::string message = openError({dir / "colour", dir / "depth", std::nullopt});
    EXPECT_NE(message.find((dir / "colour").string() + "' holds 3 images"), std::string::npos)
        << message;
    EXPECT_NE(message.find((dir / "depth").string() + "' holds 2"), std::string::npos) << message;
}

TEST(FolderPairSource, EmptyFolderIsAnError)
{
    const fs::path dir = test::scratchDir("FolderPair_empty");
    writeText(dir / "readme.txt", "no images here");
    const std::string message = openError({dir, std::nullopt, std::nullopt});
    EXPECT_NE(message.find(dir.string()), std::string::npos) << message;
    EXPECT_NE(message.find("no images"), std::string::npos) << message;
}

TEST(FolderPairSource, ColourFolderWithoutDepthGivesFramesWithoutDepth)
{
    const fs::path dir = test::scratchDir("FolderPair_nodepth");
    for (int k = 0; k < 2; ++k)
        writeImage(dir / fmt::format("{}.jpg", k), cv::Mat(8, 8, CV_8UC3, cv::Scalar::all(50)));
    const std::unique_ptr<FrameSource> source = openSource({dir, std::nullopt, std::nullopt});
    const std::vector<Frame> frames = readAll(*source);
    ASSERT_EQ(frames.size(), 2u);
    for (const Frame& f : frames) {
        EXPECT_EQ(f.color.type(), CV_8UC3);
        EXPECT_TRUE(f.depth.empty());
    }
}

TEST(SingleImageSource, GivesOneFrameWithOrWithoutDepth)
{
    const fs::path dir = test::scratchDir("SingleImage");
    writeImage(dir / "photo.png", cv::Mat(6, 8, CV_8UC3, cv::Scalar(1, 2, 3)));
    writeImage(dir / "depth.png", cv::Mat(6, 8, CV_16UC1, cv::Scalar(2500)));

    const std::unique_ptr<FrameSource> source =
        openSource({dir / "photo.png", dir / "depth.png", std::nullopt});
    EXPECT_EQ(source->frameCount(), std::optional<std::size_t>(1));
    std::optional<Frame> frame = source->next();
    ASSERT_TRUE(frame.has_value());
    EXPECT_EQ(frame->name, "photo.png");
    EXPECT_EQ(frame->color.at<cv::Vec3b>(5, 7), cv::Vec3b(1, 2, 3));
    ASSERT_EQ(frame->depth.type(), CV_32FC1);
    EXPECT_FLOAT_EQ(frame->depth.at<float>(5, 7), 2.5f); // default 1000 units per metre
    EXPECT_FALSE(source->next().has_value());

    const std::unique_ptr<FrameSource> alone = openSource({dir / "photo.png", {}, {}});
    frame = alone->next();
    ASSERT_TRUE(frame.has_value());
    EXPECT_FALSE(frame->color.empty());
    EXPECT_TRUE(frame->depth.empty());
    EXPECT_FALSE(alone->next().has_value());
}

TEST(OpenSource, MissingInputSaysItDoesNotExist)
{
    const fs::path missing = test::scratchDir("OpenSource_missing") / "nothing_here";
    EXPECT_EQ(openError({missing, std::nullopt, std::nullopt}),
              "input '" + missing.string() + "' does not exist");
    const std::string depth = openError({tumDir / "rgb" / "1305031250.261917.png", missing, {}});
    EXPECT_NE(depth.find(missing.string()), std::string::npos) << depth;
    const std::string scale = openError({tumDir, std::nullopt, 0.0});
    EXPECT_NE(scale.find("depth scale"), std::string::npos) << scale;
}

// Defect caught: a TUM list given as --depth in capitals ("DEPTH.TXT") read at the list's 5000
// units per metre but reported and checked at 1000, which warns of a wrong scale that is right.
TEST(OpenSource, DepthListScaleInAnyCase)
{
    for (const char* name : {"depth.txt", "DEPTH.TXT"})
        EXPECT_EQ(defaultDepthScale({"clip.mp4", fs::path("takes") / name, std::nullopt}), 5000.0) << name;
    EXPECT_EQ(defaultDepthScale({"clip.mp4", fs::path("takes") / "depth.png", std::nullopt}), 1000.0);
}

// Defects caught: a source that gives 16-bit depth without its scale, or with a scale other than
// the one it reads at (TUM's 5000, 1000 elsewhere, --depth-scale); depth converted although the
// caller asked for it as stored; float depth files given a scale; depth as stored not converted
// to metres for a caller that did not ask for it.
TEST(OpenSource, DepthAsStoredIsWhatTheMetresAreMadeFrom)
{
    const fs::path dir = test::scratchDir("OpenSource_units");
    cv::Mat units(6, 8, CV_16UC1);
    cv::randu(units, 0, 65536);
    units.at<std::uint16_t>(2, 3) = 0; // no measurement
    fs::create_directories(dir / "colour");
    fs::create_directories(dir / "depth");
    writeImage(dir / "colour" / "a.png", cv::Mat(6, 8, CV_8UC3, cv::Scalar(1, 2, 3)));
    writeImage(dir / "colour" / "b.png", cv::Mat(6, 8, CV_8UC3, cv::Scalar(4, 5, 6)));
    writeImage(dir / "depth" / "a.png", units);
    writeImage(dir / "depth" / "b.png", 65535 - units);
    writeImage(dir / "depth.png", units);
    cv::Mat metresFile;
    units.convertTo(metresFile, CV_32F, 1.0 / 1000.0);
    enableOpenExr();
    writeImage(dir / "depth.exr", metresFile);

    struct Case {
        const char* what;
        SourceOptions options;
        double scale; ///< units per metre the frames must carry; 0: float metres
    };
    const std::vector<Case> cases = {
        {"TUM folder", {tumDir, std::nullopt, std::nullopt}, 5000.0},
        {"TUM folder, --depth-scale", {tumDir, std::nullopt, 1000.0}, 1000.0},
        {"folder pair", {dir / "colour", dir / "depth", std::nullopt}, 1000.0},
        {"folder with one depth image", {dir / "colour", dir / "depth.png", 2000.0}, 2000.0},
        {"one image", {dir / "colour" / "a.png", dir / "depth.png", std::nullopt}, 1000.0},
        {"float depth", {dir / "colour" / "a.png", dir / "depth.exr", std::nullopt}, 0.0},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        SourceOptions stored = c.options;
        stored.depthUnits = true;
        const std::vector<Frame> asStored = readAll(*openSource(stored));
        const std::vector<Frame> inMetres = readAll(*openSource(c.options));
        ASSERT_EQ(asStored.size(), inMetres.size());
        ASSERT_FALSE(asStored.empty());
        for (std::size_t k = 0; k < asStored.size(); ++k) {
            SCOPED_TRACE(k);
            const Frame& a = asStored[k];
            const Frame& m = inMetres[k];
            ASSERT_EQ(a.depth.type(), c.scale > 0.0 ? CV_16UC1 : CV_32FC1);
            EXPECT_EQ(a.depthScale, c.scale);
            ASSERT_EQ(m.depth.type(), CV_32FC1);
            EXPECT_EQ(m.depthScale, 0.0);
            const cv::Mat converted = depthMetres(a);
            ASSERT_EQ(converted.size(), m.depth.size());
            EXPECT_EQ(cv::norm(converted, m.depth, cv::NORM_INF), 0.0) << "the same metres, bit for bit";
            EXPECT_EQ(a.name, m.name);
            EXPECT_EQ(a.timestampS, m.timestampS);
        }
    }
}

TEST(VideoFileSource, DecodesEveryFrameAndAppliesOneDepthImage)
{
    const fs::path dir = test::scratchDir("VideoFile");
    const fs::path video = dir / "clip.avi";
    {
        cv::VideoWriter writer(video.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0,
                               cv::Size(32, 24));
        ASSERT_TRUE(writer.isOpened());
        for (int k = 0; k < 4; ++k)
            writer.write(cv::Mat(24, 32, CV_8UC3, cv::Scalar::all(40.0 * k)));
    }
    writeImage(dir / "depth.png", cv::Mat(24, 32, CV_16UC1, cv::Scalar(3000)));

    const std::unique_ptr<FrameSource> source = openSource({video, dir / "depth.png", {}});
    EXPECT_NEAR(source->frameRate(), 25.0, 1e-6);
    const std::vector<Frame> frames = readAll(*source);
    ASSERT_EQ(frames.size(), 4u);
    for (std::size_t i = 0; i < frames.size(); ++i) {
        EXPECT_EQ(frames[i].index, i);
        ASSERT_EQ(frames[i].color.type(), CV_8UC3);
        EXPECT_EQ(frames[i].color.size(), cv::Size(32, 24));
        EXPECT_NEAR(cv::mean(frames[i].color)[1], 40.0 * static_cast<double>(i), 4.0); // JPEG
        ASSERT_EQ(frames[i].depth.type(), CV_32FC1);
        EXPECT_FLOAT_EQ(frames[i].depth.at<float>(0, 0), 3.0f);
    }
    EXPECT_NE(frames[0].depth.data, frames[1].depth.data); // each frame owns its depth

    const std::unique_ptr<FrameSource> colourOnly = openSource({video, {}, {}});
    const std::optional<Frame> first = colourOnly->next();
    ASSERT_TRUE(first.has_value());
    EXPECT_TRUE(first->depth.empty());
}

} // namespace
} // namespace defocus
