// SPDX-License-Identifier: LGPL-2.1-or-later
// Every option that `defocus --help` lists, through the binary: each test runs the program on a
// tiny frame (161x121, the bundled TUM texture over depth planes made for the test) and checks
// that the option changes the picture or the report the way its help line says, and the rules by
// which explicit options override --quality. The last test holds the list of options against
// --help, so that an option added without a test fails the suite.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include "filter/gl/Renderer.hpp"
#include "tests/GLTestSupport.hpp"
#include "tests/TestSupport.hpp"

namespace defocus {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 161, kHeight = 121; // odd, so that half size has to round
constexpr int kSplit = 80;                 // the depth planes meet at this column
constexpr int kMargin = 24;                // beyond any blur of these tests (16 px) and a tile

struct Ran {
    int exitCode = -1;
    std::string out; ///< stdout
    std::string err; ///< stderr
};

std::string readText(const fs::path& file)
{
    std::ifstream in(file);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

class CliFlags : public test::GLTest {
protected:
    static fs::path dir_;

    /// The fixtures, made once: colour.png (the TUM texture), depth planes (16-bit PNG, 1000 units
    /// per metre), a point and a light as float EXR, and a 2-frame folder pair.
    static void SetUpTestSuite()
    {
        GLTest::SetUpTestSuite();
        // One folder per process: CTest runs each test in a process of its own, side by side.
        dir_ = test::scratchDir(fmt::format("cli_flags/{}", ::getpid()));
        std::vector<fs::path> rgb;
        for (const auto& e : fs::directory_iterator(test::dataDir() / "tum_fr1_rpy" / "rgb"))
            rgb.push_back(e.path());
        std::sort(rgb.begin(), rgb.end());
        cv::Mat texture;
        cv::resize(cv::imread(rgb.front().string()), texture, {kWidth, kHeight}, 0, 0, cv::INTER_AREA);
        cv::imwrite((dir_ / "colour.png").string(), texture);

        const auto planes = [](int leftMm, int rightMm, cv::Size size = {kWidth, kHeight}) {
            cv::Mat depth(size, CV_16UC1, cv::Scalar(rightMm));
            depth.colRange(0, std::min(kSplit, size.width)).setTo(leftMm);
            return depth;
        };
        cv::imwrite((dir_ / "far.png").string(), planes(3000, 3000));         // all at 3 m
        cv::imwrite((dir_ / "near_far.png").string(), planes(600, 3000));     // 0.6 m | 3 m
        cv::imwrite((dir_ / "near_focus.png").string(), planes(600, 1000));   // 0.6 m | 1 m
        cv::imwrite((dir_ / "focus_far.png").string(), planes(1000, 3000));   // 1 m | 3 m
        cv::imwrite((dir_ / "far81.png").string(), planes(3000, 3000, {81, 81}));
        cv::imwrite((dir_ / "near81.png").string(), planes(700, 700, {81, 81}));

        // One pixel of linear 1.0 (white, not above it) on black, for the hexagon's shape and energy.
        cv::Mat point(81, 81, CV_32FC3, cv::Scalar::all(0));
        point.at<cv::Vec3f>(40, 40) = {1.0f, 1.0f, 1.0f};
        EXPECT_TRUE(cv::imwrite((dir_ / "point.exr").string(), point));
        // A light 30 times white on grey: bokeh sprites' input.
        cv::Mat light(81, 81, CV_32FC3, cv::Scalar::all(0.2));
        light(cv::Rect(39, 39, 3, 3)).setTo(cv::Scalar::all(30.0));
        EXPECT_TRUE(cv::imwrite((dir_ / "light.exr").string(), light));
        // One lamp 100 times white on black: all of its light goes to a bokeh sprite.
        cv::Mat lamp(81, 81, CV_32FC3, cv::Scalar::all(0));
        lamp.at<cv::Vec3f>(40, 40) = {100.0f, 100.0f, 100.0f};
        EXPECT_TRUE(cv::imwrite((dir_ / "lamp.exr").string(), lamp));
        // 8-bit colour with a clipped light, for --highlight-gain.
        cv::Mat clipped(81, 81, CV_8UC3, cv::Scalar::all(60));
        clipped(cv::Rect(38, 38, 5, 5)).setTo(cv::Scalar::all(255));
        cv::imwrite((dir_ / "clipped.png").string(), clipped);

        fs::create_directories(dir_ / "clip" / "rgb");
        fs::create_directories(dir_ / "clip" / "depth");
        cv::Mat flipped;
        cv::flip(texture, flipped, 1);
        cv::imwrite((dir_ / "clip" / "rgb" / "0.png").string(), texture);
        cv::imwrite((dir_ / "clip" / "rgb" / "1.png").string(), flipped);
        cv::imwrite((dir_ / "clip" / "depth" / "0.png").string(), planes(600, 3000));
        cv::imwrite((dir_ / "clip" / "depth" / "1.png").string(), planes(600, 3000));
        // The same colour over a depth that jumps from 1 m to 3 m at the second frame.
        fs::create_directories(dir_ / "jump" / "depth");
        fs::create_symlink(dir_ / "clip" / "rgb", dir_ / "jump" / "rgb");
        cv::imwrite((dir_ / "jump" / "depth" / "0.png").string(), planes(1000, 1000));
        cv::imwrite((dir_ / "jump" / "depth" / "1.png").string(), planes(3000, 3000));
    }

    static void TearDownTestSuite()
    {
        if (::testing::UnitTest::GetInstance()->failed_test_count() == 0)
            fs::remove_all(dir_); // kept when something failed, to look at
    }

    static fs::path file(const std::string& name) { return dir_ / name; }

    /// Runs defocus with `arguments` (quoted for the shell), stdout and stderr apart.
    static Ran defocus(const std::string& arguments)
    {
        static int count = 0;
        const fs::path out = dir_ / fmt::format("run{}.stdout", count);
        const fs::path err = dir_ / fmt::format("run{}.stderr", count++);
        const std::string command = fmt::format("'{}/defocus' {} >'{}' 2>'{}'", DEFOCUS_BINARY_DIR, arguments,
                                                out.string(), err.string());
        const int status = std::system(command.c_str());
        return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readText(out), readText(err)};
    }

    /// The 2-frame clip to a folder with `option` (a thread count) 1 and 3: the debug line that
    /// begins `debugLine` names the threads, the two folders hold the same files byte for byte,
    /// and 65 is refused with one line naming the option (exit 2).
    static void expectThreadsLeaveTheFilesAsTheyWere(const std::string& option, const std::string& debugLine)
    {
        const std::string input =
            fmt::format("'{}' --depth '{}' --focus 1 -y", file("clip/rgb").string(), file("clip/depth").string());
        const std::string stem = option.substr(2);
        const fs::path oneOut = file(stem + "_1"), threeOut = file(stem + "_3");
        const Ran one = defocus(fmt::format("{} -v {} 1 -o '{}/'", input, option, oneOut.string()));
        const Ran three = defocus(fmt::format("{} -v {} 3 -o '{}/'", input, option, threeOut.string()));
        ASSERT_EQ(one.exitCode, 0) << one.err;
        ASSERT_EQ(three.exitCode, 0) << three.err;
        EXPECT_NE(one.err.find(debugLine + " 1 thread\n"), std::string::npos) << one.err;
        EXPECT_NE(three.err.find(debugLine + " 3 threads\n"), std::string::npos) << three.err;
        std::size_t files = 0;
        for (const auto& entry : fs::recursive_directory_iterator(oneOut)) {
            if (!entry.is_regular_file())
                continue;
            ++files;
            const fs::path same = threeOut / fs::relative(entry.path(), oneOut);
            ASSERT_TRUE(fs::exists(same)) << same;
            EXPECT_EQ(readText(entry.path()), readText(same)) << same;
        }
        EXPECT_GE(files, 4u) << "two frames, their depth and the lists";
        const Ran bad = defocus(fmt::format("{} {} 65 -o '{}/'", input, option, file(stem + "_bad").string()));
        EXPECT_EQ(bad.exitCode, 2);
        EXPECT_NE(bad.err.find(option + " must be between 0 and 64"), std::string::npos) << bad.err;
    }

    /// The renderer `defocus --info` names is a software one (gl::isSoftwareRenderer()): the
    /// renderer's own choices (depth prep, the presets' precision) are the CPU's and 32f there.
    static bool softwareRenderer()
    {
        const std::string info = defocus("--info").out;
        const std::size_t at = info.find("GL renderer:  ");
        EXPECT_NE(at, std::string::npos) << info;
        const std::size_t from = at + std::string_view("GL renderer:  ").size();
        return at != std::string::npos && gl::isSoftwareRenderer(info.substr(from, info.find('\n', from) - from));
    }

    /// The picture `arguments` give, written to a fresh file of type `extension` (".png": 8-bit
    /// sRGB, ".exr": linear float); an empty Mat (and a failure) when the run fails.
    static cv::Mat render(const std::string& arguments, const std::string& extension = ".png")
    {
        static int count = 0;
        const fs::path output = dir_ / fmt::format("out{}{}", count++, extension);
        const Ran run = defocus(arguments + " -q -o '" + output.string() + "'");
        EXPECT_EQ(run.exitCode, 0) << arguments << "\n" << run.err;
        return cv::imread(output.string(), cv::IMREAD_UNCHANGED);
    }

    /// The TUM texture over depth `depth` (one of the planes above), --focus 1 unless set.
    static cv::Mat texture(const std::string& depth, const std::string& options,
                           const std::string& extension = ".png")
    {
        return render(fmt::format("'{}' --depth '{}' {}", file("colour.png").string(), file(depth).string(),
                                  options.find("--focus") == std::string::npos ? "--focus 1 " + options : options),
                      extension);
    }

    static cv::Mat input() { return cv::imread(file("colour.png").string()); }
};

fs::path CliFlags::dir_;

/// Mean absolute difference per channel value, over `roi` (all of it when empty).
double difference(const cv::Mat& a, const cv::Mat& b, cv::Rect roi = {})
{
    if (a.empty() || b.empty() || a.size() != b.size())
        return -1.0;
    if (roi.area() == 0)
        roi = cv::Rect({0, 0}, a.size());
    cv::Mat da, db;
    a(roi).convertTo(da, CV_64F);
    b(roi).convertTo(db, CV_64F);
    const cv::Scalar m = cv::mean(cv::abs(da - db));
    return (m[0] + m[1] + m[2]) / 3.0;
}

bool identical(const cv::Mat& a, const cv::Mat& b)
{
    return !a.empty() && a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

const cv::Rect kLeft(0, 0, kSplit - kMargin, kHeight);
const cv::Rect kRight(kSplit + kMargin, 0, kWidth - kSplit - kMargin, kHeight);

// --- the lens --------------------------------------------------------------------------------

// Defect: --focal-length ignored or inverted. A point at 3 m, focus 1 m, f/1.4 on 36 mm over
// 161 px: 35 mm blurs it by about 2.6 px, 50 mm by 5.3 px, 85 mm by 15 px.
TEST_F(CliFlags, FocalLengthLongerLensBlursMore)
{
    const cv::Mat in = input();
    const double mm35 = difference(texture("far.png", "--f-number 1.4 --focal-length 35"), in);
    const double mm50 = difference(texture("far.png", "--f-number 1.4 --focal-length 50"), in);
    const double mm85 = difference(texture("far.png", "--f-number 1.4 --focal-length 85"), in);
    EXPECT_LT(mm35, mm50);
    EXPECT_LT(mm50, mm85);
}

// Defect: --sensor-width ignored, or multiplied where it divides (px = mm x width / sensor width).
TEST_F(CliFlags, SensorWidthSmallerSensorBlursMore)
{
    const cv::Mat in = input();
    const double w24 = difference(texture("far.png", "--f-number 1.4 --sensor-width 24"), in);
    const double w36 = difference(texture("far.png", "--f-number 1.4 --sensor-width 36"), in);
    const double w72 = difference(texture("far.png", "--f-number 1.4 --sensor-width 72"), in);
    EXPECT_GT(w24, w36);
    EXPECT_GT(w36, w72);
}

// Defect: --fov-from ignored, or the two conventions swapped. With the field of view of the focal
// length the same blur spans (S - f) / S as many pixels as with the sensor at the image distance:
// 0.8 at 100 mm focused at 0.5 m, and no difference at infinity.
TEST_F(CliFlags, FovFromImageDistanceBlursMoreUnlessFocusedAtInfinity)
{
    const cv::Mat in = input();
    const std::string lens = "--focus 0.5 --focal-length 100 --f-number 2.8 --max-coc 64";
    const double image = difference(texture("far.png", lens + " --fov-from image-distance"), in);
    const double focal = difference(texture("far.png", lens + " --fov-from focal-length"), in);
    EXPECT_GT(image, focal * 1.05) << "image-distance " << image << ", focal-length " << focal;
    EXPECT_TRUE(identical(texture("far.png", "--focus inf --f-number 1.4 --fov-from image-distance"),
                          texture("far.png", "--focus inf --f-number 1.4 --fov-from focal-length")));
}

// Defect: --coc-model ignored (focal-range runs the thin lens). The focal-range model does not
// know the aperture: its picture is the same at f/1.4 and f/8, the thin lens's is not.
TEST_F(CliFlags, CocModelFocalRangeIgnoresTheAperture)
{
    const std::string range = "--coc-model focal-range --near 0.5 --far 6 --max-coc 16";
    const cv::Mat rangeOpen = texture("near_far.png", range + " --f-number 1.4");
    EXPECT_TRUE(identical(rangeOpen, texture("near_far.png", range + " --f-number 8")));
    const cv::Mat thinOpen = texture("near_far.png", "--coc-model thin-lens --max-coc 16 --f-number 1.4");
    EXPECT_FALSE(identical(thinOpen, texture("near_far.png", "--coc-model thin-lens --max-coc 16 --f-number 8")));
    EXPECT_FALSE(identical(rangeOpen, thinOpen));
}

// Defects: --near ignored, applied to the far side, or used by the thin lens. Moving the near
// limit towards the focus blurs the near plane (0.6 m) more and leaves the far plane's pixels
// (3 m, beyond the near blur's reach) unchanged; the thin lens does not read it.
TEST_F(CliFlags, NearMovesOnlyTheNearBlur)
{
    const cv::Mat in = input();
    const std::string range = "--coc-model focal-range --far 6 --max-coc 16";
    const cv::Mat loose = texture("near_far.png", range + " --near 0.3"); // 0.6 m: 9 px
    const cv::Mat tight = texture("near_far.png", range + " --near 0.5"); // 0.6 m: 13 px
    EXPECT_GT(difference(tight, in, kLeft), difference(loose, in, kLeft) + 0.5);
    EXPECT_EQ(difference(tight, loose, kRight), 0.0);
    EXPECT_TRUE(identical(texture("near_far.png", "--f-number 2 --near 0.3"),
                          texture("near_far.png", "--f-number 2 --near 0.5")));
}

// Defects: --far ignored, applied to the near side, or used by the thin lens.
TEST_F(CliFlags, FarMovesOnlyTheFarBlur)
{
    const cv::Mat in = input();
    const std::string range = "--coc-model focal-range --near 0.3 --max-coc 16";
    const cv::Mat loose = texture("near_far.png", range + " --far 6");   // 3 m: 6.4 px
    const cv::Mat tight = texture("near_far.png", range + " --far 3.5"); // 3 m: 12.8 px
    EXPECT_GT(difference(tight, in, kRight), difference(loose, in, kRight) + 0.5);
    EXPECT_EQ(difference(tight, loose, kLeft), 0.0);
    EXPECT_TRUE(identical(texture("near_far.png", "--f-number 2 --far 3.5"),
                          texture("near_far.png", "--f-number 2 --far 6")));
}

// Defect: --max-coc ignored (no clamp) or clamping to the wrong value: at f/1.4 and 85 mm the far
// plane's 15 px is clamped to 4 px and 8 px; above 15 px the clamp changes nothing.
TEST_F(CliFlags, MaxCocClampsTheBlur)
{
    const cv::Mat in = input();
    const std::string lens = "--f-number 1.4 --focal-length 85";
    const double c4 = difference(texture("far.png", lens + " --max-coc 4"), in);
    const double c8 = difference(texture("far.png", lens + " --max-coc 8"), in);
    EXPECT_LT(c4, c8);
    EXPECT_TRUE(identical(texture("far.png", lens + " --max-coc 32"), texture("far.png", lens + " --max-coc 64")));
}

// Defect: --blade-rotation ignored. A point's hexagon with a corner on top (0) has a narrow top
// row; rotated by 30 degrees an edge is on top, as wide as a side (half the 21 px diameter).
TEST_F(CliFlags, BladeRotationPutsACornerOrAnEdgeOnTop)
{
    const auto topRowWidth = [&](const std::string& rotation) {
        const cv::Mat out =
            render(fmt::format("'{}' --depth '{}' --coc-model focal-range --focus 1 --near 0.5 --far 2 --max-coc 21 --quality "
                               "high --no-highlight-sprites --blade-rotation {}",
                               file("point.exr").string(), file("far81.png").string(), rotation),
                   ".exr");
        if (out.empty())
            return -1;
        std::vector<cv::Mat> channels;
        cv::split(out, channels);
        double peak = 0;
        cv::minMaxLoc(channels[1], nullptr, &peak);
        const cv::Mat lit = channels[1] > 0.25 * peak;
        for (int y = 0; y < lit.rows; ++y)
            if (const int n = cv::countNonZero(lit.row(y)); n > 0)
                return n;
        return 0;
    };
    const int corner = topRowWidth("0");
    const int edge = topRowWidth("30");
    EXPECT_GT(corner, 0);
    EXPECT_LE(corner, 3);
    EXPECT_GE(edge, 7) << "corner on top: " << corner << " px";
}

// Defect: --blades or --aperture-ratio ignored, or the shape drawn the wrong way round, or its
// light not kept. A lamp 100 times white becomes the aperture's shape, 21 px across, as Blender
// Cycles draws it: behind the focus a 5-bladed aperture at rotation 0 has a flat edge on the right
// (an edge's normal points right) and a corner on the left; in front of the focus the lens turns
// it by 180 degrees; the circle covers pi / (3 sqrt(3) / 2) = 1.21 times the hexagon's area; a
// ratio of 2 makes an oval twice as tall as wide. Each keeps the lamp's light (the sum, 100).
TEST_F(CliFlags, BladesAndApertureRatioShapeTheLights)
{
    struct Shape {
        cv::Mat lit; // the pixels above a quarter of the peak
        double light = 0.0;
    };
    const auto lamp = [&](const std::string& depth, const std::string& aperture) {
        const cv::Mat out = render(fmt::format("'{}' --depth '{}' --coc-model focal-range --focus 1 --near 0.5 --far 2 "
                                               "--max-coc 21 --quality high {}",
                                               file("lamp.exr").string(), file(depth).string(), aperture),
                                   ".exr");
        Shape shape;
        if (out.empty())
            return shape;
        std::vector<cv::Mat> channels;
        cv::split(out, channels);
        double peak = 0;
        cv::minMaxLoc(channels[1], nullptr, &peak);
        shape.lit = channels[1] > 0.25 * peak;
        shape.light = cv::sum(channels[1])[0];
        return shape;
    };
    // The lit pixels of the leftmost and rightmost lit columns.
    const auto ends = [](const cv::Mat& lit) {
        const cv::Rect box = cv::boundingRect(lit);
        return std::pair{cv::countNonZero(lit.col(box.x)), cv::countNonZero(lit.col(box.x + box.width - 1))};
    };
    const Shape hexagon = lamp("far81.png", "");
    const Shape circle = lamp("far81.png", "--blades 0");
    const Shape pentagon = lamp("far81.png", "--blades 5");
    const Shape nearPentagon = lamp("near81.png", "--blades 5");
    const Shape oval = lamp("far81.png", "--blades 0 --aperture-ratio 2");
    for (const Shape* s : {&hexagon, &circle, &pentagon, &nearPentagon, &oval}) {
        ASSERT_FALSE(s->lit.empty());
        EXPECT_NEAR(s->light, 100.0, 1.0);
    }
    const double areas = static_cast<double>(cv::countNonZero(circle.lit)) / cv::countNonZero(hexagon.lit);
    EXPECT_NEAR(areas, 1.209, 0.08);
    // The pentagon's edge is 2 R sin 36 deg = 12 px long; its corner a column of a few pixels.
    const auto [farLeft, farRight] = ends(pentagon.lit);
    EXPECT_LE(farLeft, 4);
    EXPECT_GE(farRight, 9);
    const auto [nearLeft, nearRight] = ends(nearPentagon.lit);
    EXPECT_GE(nearLeft, 6); // 12.6 px across in front: an edge of 7 px
    EXPECT_LE(nearRight, 4);
    const cv::Rect box = cv::boundingRect(oval.lit);
    EXPECT_NEAR(static_cast<double>(box.height) / box.width, 2.0, 0.25) << box;
}

// Defect: the gather (everything but the lights above white) not squeezed with the aperture: a
// point of white through a 2:1 aperture, sprites off, spread as a round hexagon, 1.21 times as
// wide as the oval's truth. The rhombi squeezed keep its light and draw a hexagon twice as tall as
// wide, the corner on top (21 px) over 21 / 2 cos 30 deg = 9 px.
TEST_F(CliFlags, ApertureRatioSqueezesTheGather)
{
    const auto point = [&](const std::string& aperture) {
        return render(fmt::format("'{}' --depth '{}' --coc-model focal-range --focus 1 --near 0.5 --far 2 --max-coc 21 "
                                  "--quality high --no-highlight-sprites {}",
                                  file("point.exr").string(), file("far81.png").string(), aperture),
                      ".exr");
    };
    for (const std::string aperture : {"--blades 6 --aperture-ratio 2", "--blades 0 --aperture-ratio 2"}) {
        const cv::Mat out = point(aperture);
        ASSERT_FALSE(out.empty()) << aperture;
        std::vector<cv::Mat> channels;
        cv::split(out, channels);
        EXPECT_NEAR(cv::sum(channels[1])[0], 1.0, 0.01) << aperture;
        if (aperture.find("--blades 6") == std::string::npos)
            continue; // the circle's gather: the same hexagon, 1.1 times as large
        double peak = 0;
        cv::minMaxLoc(channels[1], nullptr, &peak);
        const cv::Rect box = cv::boundingRect(channels[1] > 0.25 * peak);
        // 2 / cos 30 deg = 2.31, within a pixel of the 9 px width (+-0.26); unsqueezed: 1.1.
        EXPECT_NEAR(static_cast<double>(box.height) / box.width, 2.0 / std::cos(std::numbers::pi / 6), 0.3)
            << aperture << ": " << box;
    }
}

// Defect: --hexagon ignored or the kernels swapped. The rhombi keep a point's light (the sum of
// the output equals the input's 1.0); McIntosh's chain takes the minimum of two blurs, which
// loses light where the two disagree (README: three quarters of a highlight's energy).
TEST_F(CliFlags, HexagonRhombiKeepALightsEnergyAndMcIntoshsMinimumDoesNot)
{
    const auto energy = [&](const std::string& kernel) {
        const cv::Mat out =
            render(fmt::format("'{}' --depth '{}' --coc-model focal-range --focus 1 --near 0.5 --far 2 --max-coc 21 --quality "
                               "high --no-highlight-sprites --hexagon {}",
                               file("point.exr").string(), file("far81.png").string(), kernel),
                   ".exr");
        return out.empty() ? -1.0 : cv::sum(out)[1];
    };
    const double rhombi = energy("rhombi");
    const double mcintosh = energy("mcintosh");
    EXPECT_NEAR(rhombi, 1.0, 0.03);
    EXPECT_LT(mcintosh, 0.9 * rhombi) << "rhombi " << rhombi;
    EXPECT_GT(mcintosh, 0.3 * rhombi) << "rhombi " << rhombi;
}

// --- quality -----------------------------------------------------------------------------------

// Defects: --quality ignored, a preset with the wrong taps or size, explicit options not
// overriding the preset (or the preset overriding them when it comes after them). fast =
// balanced with 4 taps; high = balanced with 12 taps at full size; --hexagon and --near-field
// override each preset (the plan --explain prints says what ran).
TEST_F(CliFlags, QualityPresetsAndTheOptionsThatOverrideThem)
{
    const std::string lens = "--f-number 1.4 --focal-length 85 --max-coc 32 "; // lines longer than 6 taps
    const cv::Mat balanced = texture("near_far.png", lens);
    const cv::Mat fast = texture("near_far.png", lens + "--quality fast");
    const cv::Mat high = texture("near_far.png", lens + "--quality high");
    EXPECT_FALSE(identical(balanced, fast));
    EXPECT_FALSE(identical(balanced, high));
    EXPECT_TRUE(identical(fast, texture("near_far.png", lens + "--samples 4 --quality balanced")));
    EXPECT_TRUE(identical(high, texture("near_far.png", lens + "--samples 12 --resolution full")));
    EXPECT_TRUE(identical(texture("near_far.png", lens + "--quality high --resolution half"),
                          texture("near_far.png", lens + "--samples 12")));

    const auto plan = [&](const std::string& options) {
        const Ran run = defocus(fmt::format("'{}' --depth '{}' --focus 1 {} --explain -q -y -o '{}' {}",
                                            file("colour.png").string(), file("near_focus.png").string(), lens,
                                            file("explain.png").string(), options));
        EXPECT_EQ(run.exitCode, 0) << run.err;
        return run.out;
    };
    const std::string fastPlan = plan("--quality fast");
    EXPECT_NE(fastPlan.find("coc > rhombi-1 > rhombi-2 > prefilter > upscale"), std::string::npos) << fastPlan;
    EXPECT_NE(fastPlan.find("half size"), std::string::npos) << fastPlan;
    EXPECT_NE(fastPlan.find("near field on"), std::string::npos) << fastPlan;
    const std::string highPlan = plan("--quality high --hexagon mcintosh");
    EXPECT_NE(highPlan.find("coc > horizontal > diagonal-a > diagonal-b"), std::string::npos) << highPlan;
    EXPECT_EQ(highPlan.find("half size"), std::string::npos) << highPlan;
    const std::string balancedPlan = plan("--no-near-field --quality balanced");
    EXPECT_NE(balancedPlan.find("near field off"), std::string::npos) << balancedPlan;
}

// Defect: --samples ignored: 2 taps per line and 12 give different pictures, and 2 taps leave
// the kernel's gaps (a rougher, less blurred-looking result) that 12 fill.
TEST_F(CliFlags, SamplesSetTheTapsPerLine)
{
    const cv::Mat two = texture("far.png", "--f-number 1.4 --focal-length 85 --max-coc 16 --samples 2");
    const cv::Mat twelve = texture("far.png", "--f-number 1.4 --focal-length 85 --max-coc 16 --samples 12");
    EXPECT_GT(difference(two, twelve), 0.2);
}

// Defect: --precision ignored, or the preset's precision not the renderer's. The linear output
// of 16F targets differs from that of 32F ones, and without the option the preset runs the
// renderer's: 32F on a software renderer (llvmpipe), 16F on a GPU.
TEST_F(CliFlags, PrecisionSetsTheTargetFormat)
{
    const std::string lens = "--f-number 1.4 --max-coc 16";
    const cv::Mat preset = texture("near_far.png", lens, ".exr");
    const cv::Mat f32 = texture("near_far.png", lens + " --precision 32f", ".exr");
    const cv::Mat f16 = texture("near_far.png", lens + " --precision 16f", ".exr");
    EXPECT_TRUE(identical(preset, softwareRenderer() ? f32 : f16));
    ASSERT_FALSE(f16.empty());
    EXPECT_GT(cv::norm(f16, f32, cv::NORM_INF), 0.0);
}

// Defects: --resolution ignored, half size changing the frame's size (161x121 is odd), or losing
// the in-focus pixels it promises to keep: the plane at the focus stays the input's, to the bit.
TEST_F(CliFlags, ResolutionHalfKeepsTheSizeAndTheInFocusPixels)
{
    const cv::Mat in = input();
    const cv::Mat half = texture("focus_far.png", "--f-number 1.4 --max-coc 16 --resolution half");
    const cv::Mat full = texture("focus_far.png", "--f-number 1.4 --max-coc 16 --resolution full");
    ASSERT_EQ(half.size(), in.size());
    EXPECT_EQ(difference(half, in, kLeft), 0.0);
    EXPECT_GT(difference(half, in, kRight), 1.0);
    EXPECT_FALSE(identical(half, full));
}

// Defect: --near-field ignored. The blurred foreground (0.6 m) spreads over the plane at the focus
// behind it with the near field, and does not without it: there the in-focus pixels next to
// the edge stay the input's.
TEST_F(CliFlags, NearFieldSpreadsTheForegroundOverWhatIsBehind)
{
    const cv::Mat in = input();
    const cv::Rect band(kSplit + 1, 0, 4, kHeight);
    const std::string lens = "--f-number 1.4 --focal-length 85 --max-coc 16"; // 0.6 m: 16 px
    EXPECT_GT(difference(texture("near_focus.png", lens + " --near-field"), in, band), 1.0);
    EXPECT_EQ(difference(texture("near_focus.png", lens + " --no-near-field"), in, band), 0.0);
}

// Defect: --highlight-sprites / --no-highlight-sprites ignored. A light 30 times white is
// scattered as a sprite by default, and only gathered without them; --explain says which.
TEST_F(CliFlags, HighlightSpritesScatterLightsAboveWhite)
{
    const auto run = [&](const std::string& option) {
        const fs::path out = file("sprites" + std::to_string(option.size()) + ".exr");
        const Ran r = defocus(fmt::format("'{}' --depth '{}' --coc-model focal-range --focus 1 --near 0.5 --far 2 --max-coc 21 "
                                          "--explain -q -o '{}' {}",
                                          file("light.exr").string(), file("far81.png").string(), out.string(), option));
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return std::make_pair(r.out, cv::imread(out.string(), cv::IMREAD_UNCHANGED));
    };
    const auto [onByDefault, spritesOn] = run("");
    const auto [off, spritesOff] = run("--no-highlight-sprites");
    EXPECT_NE(onByDefault.find("(bokeh sprites)"), std::string::npos) << onByDefault;
    EXPECT_EQ(off.find("(bokeh sprites)"), std::string::npos) << off;
    EXPECT_NE(off.find("highlights"), std::string::npos) << off;
    ASSERT_FALSE(spritesOn.empty());
    EXPECT_GT(cv::norm(spritesOn, spritesOff, cv::NORM_INF), 0.1);
    EXPECT_TRUE(identical(spritesOn, run("--highlight-sprites").second));
}

// Defect: --highlight-gain ignored. A clipped light in 8-bit input blooms: with the gain its
// blurred hexagon holds more light than without, and --explain reports the recovery.
TEST_F(CliFlags, HighlightGainMakesClippedLightsBloom)
{
    const auto run = [&](const std::string& gain) {
        const fs::path out = file("gain" + gain + ".exr");
        const Ran r = defocus(fmt::format("'{}' --depth '{}' --coc-model focal-range --focus 1 --near 0.5 --far 2 --max-coc 21 "
                                          "--explain -q -o '{}' --highlight-gain {}",
                                          file("clipped.png").string(), file("far81.png").string(), out.string(), gain));
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return std::make_pair(r.out, cv::imread(out.string(), cv::IMREAD_UNCHANGED));
    };
    const auto [plain, off] = run("1");
    const auto [explained, on] = run("8");
    ASSERT_FALSE(on.empty());
    ASSERT_FALSE(off.empty());
    // The light above the grey around it, in the 31x31 pixels about the light.
    const auto excess = [](const cv::Mat& out) {
        const cv::Rect centre(25, 25, 31, 31);
        return cv::sum(out(centre))[1] - cv::mean(out(cv::Rect(0, 0, 10, 10)))[1] * centre.area();
    };
    EXPECT_GT(excess(on), 3.0 * excess(off)) << "without the gain " << excess(off);
    EXPECT_NE(explained.find("recovered x8"), std::string::npos) << explained;
    EXPECT_EQ(plain.find("recovered"), std::string::npos) << plain;
}

// --- what is written ---------------------------------------------------------------------------

// Defects: --view writing the wrong stage, or every view the same picture. input is the frame
// itself (the sRGB round trip is exact at 8 bits); the four blur stages differ from each other
// and from it; depth and coc draw the two planes apart, coc the near plane blue and the far red.
TEST_F(CliFlags, ViewWritesEachStage)
{
    const cv::Mat in = input();
    std::map<std::string, cv::Mat> views;
    for (const char* view : {"input", "horizontal", "diagonal-a", "diagonal-b", "composite", "depth", "coc"})
        views[view] = texture("near_far.png", std::string("--f-number 1.4 --max-coc 16 --quality high --view ") + view);
    EXPECT_LE(difference(views["input"], in), 0.01);
    const std::vector<std::string> stages{"horizontal", "diagonal-a", "diagonal-b", "composite"};
    for (std::size_t i = 0; i < stages.size(); ++i) {
        EXPECT_GT(difference(views[stages[i]], in), 0.5) << stages[i];
        for (std::size_t j = i + 1; j < stages.size(); ++j)
            EXPECT_FALSE(identical(views[stages[i]], views[stages[j]])) << stages[i] << " = " << stages[j];
    }
    const cv::Scalar nearCoc = cv::mean(views["coc"](cv::Rect(10, 10, 40, 60)));
    const cv::Scalar farCoc = cv::mean(views["coc"](cv::Rect(kWidth - 50, 10, 40, 60)));
    EXPECT_GT(nearCoc[0], nearCoc[2] + 20) << "near: BGR " << nearCoc;
    EXPECT_GT(farCoc[2], farCoc[0] + 20) << "far: BGR " << farCoc;
    const cv::Scalar nearDepth = cv::mean(views["depth"](cv::Rect(10, 10, 40, 60)));
    const cv::Scalar farDepth = cv::mean(views["depth"](cv::Rect(kWidth - 50, 10, 40, 60)));
    EXPECT_GT(cv::norm(nearDepth - farDepth), 30.0);
}

// Defect: --fps ignored (the video takes the input's rate, 30 Hz for a folder of images).
TEST_F(CliFlags, FpsSetsTheVideosRate)
{
    const auto rate = [&](const std::string& option) {
        const fs::path out = file("rate" + std::to_string(option.size()) + ".avi");
        const Ran r = defocus(fmt::format("'{}' --depth '{}' --focus 1 -q -o '{}' {}", file("clip/rgb").string(),
                                          file("clip/depth").string(), out.string(), option));
        EXPECT_EQ(r.exitCode, 0) << r.err;
        cv::VideoCapture video(out.string());
        EXPECT_EQ(video.get(cv::CAP_PROP_FRAME_COUNT), 2.0);
        return video.get(cv::CAP_PROP_FPS);
    };
    EXPECT_NEAR(rate("--fps 12"), 12.0, 0.01);
    EXPECT_NEAR(rate(""), 30.0, 0.01);
}

// Defect: --timings writing nothing, a frame missing, or GPU passes left out. Each frame has its
// wall times, the summary counts every frame, and with timer queries each pass is there.
TEST_F(CliFlags, TimingsWritesEveryFrameAndTheSummary)
{
    const fs::path json = file("timings.json");
    const Ran r = defocus(fmt::format("'{}' --depth '{}' --focus 1 --f-number 1.4 -q -o '{}' --timings '{}'",
                                      file("clip/rgb").string(), file("clip/depth").string(),
                                      file("timed/").string(), json.string()));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    std::ifstream in(json);
    ASSERT_TRUE(in) << json;
    const nlohmann::json doc = nlohmann::json::parse(in);
    EXPECT_EQ(doc["width"], kWidth);
    EXPECT_EQ(doc["height"], kHeight);
    ASSERT_EQ(doc["frames"].size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_EQ(doc["frames"][i]["index"], i);
        EXPECT_GT(doc["frames"][i]["total_ms"].get<double>(), 0.0);
    }
    EXPECT_EQ(doc["summary"]["total_ms"]["frames"], 2);
    if (defocus("--info").out.find("GPU timers:   yes") != std::string::npos)
        for (const char* pass : {"coc", "rhombi-1", "rhombi-2", "upscale"}) {
            EXPECT_EQ(doc["summary"]["gpu_ms"][pass]["frames"], 2) << pass;
            for (std::size_t i = 0; i < 2; ++i)
                EXPECT_TRUE(doc["frames"][i]["gpu_ms"].contains(pass)) << "frame " << i << ", " << pass;
        }
}

// Defect: --explain silent, or printing when not asked: one line per frame on stdout, what the
// plan ran (here the rhombi with the near field), and a frame all in focus said to be one.
TEST_F(CliFlags, ExplainPrintsThePlanOfEachFrame)
{
    const std::string clip = fmt::format("'{}' --depth '{}' --focus 1 -q", file("clip/rgb").string(),
                                         file("clip/depth").string());
    const Ran blurred = defocus(clip + " --f-number 1.4 --explain -o '" + file("explained/").string() + "'");
    ASSERT_EQ(blurred.exitCode, 0) << blurred.err;
    EXPECT_NE(blurred.out.find("frame 0: coc > rhombi-1 > rhombi-2"), std::string::npos) << blurred.out;
    EXPECT_NE(blurred.out.find("\nframe 1: coc > rhombi-1 > rhombi-2"), std::string::npos) << blurred.out;
    EXPECT_NE(blurred.out.find("near field on"), std::string::npos) << blurred.out;
    const Ran sharp = defocus(clip + " --max-coc 0.4 --explain -o '" + file("sharp/").string() + "'");
    EXPECT_NE(sharp.out.find("frame 0: all in focus"), std::string::npos) << sharp.out;
    const Ran quiet = defocus(clip + " --f-number 1.4 -o '" + file("unexplained/").string() + "'");
    EXPECT_EQ(quiet.out.find("frame 0:"), std::string::npos) << quiet.out;
}

// Defect: --always-on ignored: a frame all in focus is passed through by the plan (no pass runs,
// the summary has no GPU passes) and rendered by every pass with --always-on, to the same bits.
TEST_F(CliFlags, AlwaysOnRunsEveryPassWithTheSameResult)
{
    const auto run = [&](const std::string& option) {
        const fs::path out = file("always" + std::to_string(option.size()) + ".png");
        const Ran r = defocus(fmt::format("'{}' --depth '{}' --focus 1 --max-coc 0.4 -o '{}' {}",
                                          file("colour.png").string(), file("near_far.png").string(), out.string(),
                                          option));
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return std::make_pair(r.out, cv::imread(out.string(), cv::IMREAD_UNCHANGED));
    };
    const auto [planned, passedThrough] = run("");
    const auto [always, rendered] = run("--always-on");
    EXPECT_NE(planned.find("GPU per pass: n/a"), std::string::npos) << planned;
    if (defocus("--info").out.find("GPU timers:   yes") != std::string::npos) {
        // The passes in the order they ran: depth prep first where the GPU does it.
        const std::size_t passes = always.find("GPU per pass: ");
        EXPECT_NE(passes, std::string::npos) << always;
        EXPECT_NE(always.find(" coc ", passes), std::string::npos) << always;
    }
    EXPECT_TRUE(identical(passedThrough, rendered));
    EXPECT_TRUE(identical(passedThrough, input()));
}

// Defect: --contact-sheet not written, or --contact-frame ignored; a frame index beyond the clip
// writes nothing and exits 0: it must fail (1) in one line naming the option, before any frame.
TEST_F(CliFlags, ContactSheetOfTheChosenFrameAndAnErrorBeyondTheClip)
{
    const std::string clip = fmt::format("'{}' --depth '{}' --focus 1 --f-number 1.4 -q", file("clip/rgb").string(),
                                         file("clip/depth").string());
    const fs::path sheet0 = file("sheet0.png"), sheet1 = file("sheet1.png");
    EXPECT_EQ(defocus(clip + " -o '" + file("s0/").string() + "' --contact-sheet '" + sheet0.string() + "'").exitCode,
              0);
    const Ran second = defocus(clip + " -o '" + file("s1/").string() + "' --contact-sheet '" + sheet1.string() +
                               "' --contact-frame 1");
    EXPECT_EQ(second.exitCode, 0) << second.err;
    const cv::Mat a = cv::imread(sheet0.string()), b = cv::imread(sheet1.string());
    ASSERT_FALSE(a.empty());
    ASSERT_FALSE(b.empty());
    EXPECT_GT(a.cols * a.rows, 8 * kWidth * kHeight); // every view and the plan, labelled
    EXPECT_FALSE(identical(a, b));                     // frame 1 is frame 0 mirrored
    EXPECT_EQ((second.err + second.out).find("warning"), std::string::npos) << second.err;

    const fs::path beyond = file("sheet5.png");
    const Ran r = defocus(clip + " -o '" + file("s5/").string() + "' --contact-sheet '" + beyond.string() +
                          "' --contact-frame 5");
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("error: --contact-frame 5 is beyond the 2 frames of"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(beyond));
    EXPECT_FALSE(fs::exists(file("s5"))) << "refused before the output is made";
}

// Defect: --focus-point ignored (the centre measured): at a pixel of the near plane the automatic
// focus is 0.6 m, at one of the far plane 3 m (--explain prints each frame's focus).
TEST_F(CliFlags, FocusPointMeasuresTheFocusThere)
{
    const auto focus = [&](const std::string& point) {
        const Ran r = defocus(fmt::format("'{}' --depth '{}' --focus auto --focus-point {} --explain -q -o '{}'",
                                          file("colour.png").string(), file("near_far.png").string(), point,
                                          file("point" + std::to_string(point.size()) + point.substr(0, 2) + ".png").string()));
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return r.out;
    };
    EXPECT_NE(focus("20,60").find("frame 0: focus 0.6000 m"), std::string::npos) << focus("20,60");
    EXPECT_NE(focus("140,60").find("frame 0: focus 3.0000 m"), std::string::npos) << focus("140,60");
    // Defect: a point outside the frame accepted (its window clamped to the border, or empty) and
    // the run exiting 0: it is refused in one line naming the option and the frame's size.
    const Ran outside = defocus(fmt::format("'{}' --depth '{}' --focus-point 161,60 -q -o '{}'",
                                            file("colour.png").string(), file("near_far.png").string(),
                                            file("outside.png").string()));
    EXPECT_EQ(outside.exitCode, 1) << outside.err;
    EXPECT_NE(outside.err.find("error: --focus-point 161,60 is outside the 161x121 frame (X 0 to 160, Y 0 to "
                               "120)"),
              std::string::npos)
        << outside.err;
    EXPECT_FALSE(fs::exists(file("outside.png")));
}

// Defect: --tau ignored: tracking focus jumps with the depth (1 m, then 3 m) at once with --tau
// 0, and moves only a little of the way in one frame (1/30 s) with a time constant of 10 s.
TEST_F(CliFlags, TauDampsTheTrackedFocus)
{
    const auto explain = [&](const std::string& tau) {
        const Ran r = defocus(fmt::format("'{}' --depth '{}' --focus track --tau {} --explain -q -o '{}'",
                                          file("jump/rgb").string(), file("jump/depth").string(), tau,
                                          file("tau" + tau + "/").string()));
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return r.out;
    };
    const std::string at0 = explain("0"), at10 = explain("10");
    EXPECT_NE(at0.find("frame 1: focus 3.0000 m"), std::string::npos) << at0;
    EXPECT_EQ(at10.find("frame 1: focus 3.0000 m"), std::string::npos) << at10;
    EXPECT_NE(at10.find("frame 1: focus 1.0"), std::string::npos) << at10;
}

// Defects: --codec ignored (the container's default written), --image-format ignored.
TEST_F(CliFlags, CodecAndImageFormatChooseWhatIsWritten)
{
    const std::string clip = fmt::format("'{}' --depth '{}' --focus 1 -q", file("clip/rgb").string(),
                                         file("clip/depth").string());
    const auto fourcc = [&](const std::string& name, const std::string& option) {
        const fs::path out = file(name);
        const Ran r = defocus(clip + " -o '" + out.string() + "' " + option);
        EXPECT_EQ(r.exitCode, 0) << r.err;
        cv::VideoCapture video(out.string());
        const auto code = static_cast<unsigned>(video.get(cv::CAP_PROP_FOURCC));
        return std::string{static_cast<char>(code & 0xff), static_cast<char>(code >> 8 & 0xff),
                           static_cast<char>(code >> 16 & 0xff), static_cast<char>(code >> 24 & 0xff)};
    };
    EXPECT_EQ(fourcc("default.mkv", ""), "FFV1");
    const std::string mjpg = fourcc("mjpg.mkv", "--codec mjpg"); // Matroska tags it "mjpe" or "MJPG"
    EXPECT_TRUE(mjpg == "MJPG" || mjpg == "mjpe") << mjpg;

    const auto written = [&](const std::string& name, const std::string& option) {
        const fs::path out = file(name);
        const Ran r = defocus(clip + " -o '" + out.string() + "/' " + option);
        EXPECT_EQ(r.exitCode, 0) << r.err;
        std::set<std::string> extensions;
        // The frames: the files at the top of the folder but the TUM lists (depth/ has its own).
        for (const auto& e : fs::directory_iterator(out))
            if (e.is_regular_file() && e.path().extension() != ".txt")
                extensions.insert(e.path().extension().string());
        return extensions;
    };
    EXPECT_EQ(written("png_frames", ""), std::set<std::string>{".png"});
    EXPECT_EQ(written("exr_frames", "--image-format exr"), std::set<std::string>{".exr"});

    // Defect: a library's own console line in a clean run (OpenCV's FFmpeg wrapper prints "tag
    // 0x30395056/'VP90' is not supported with codec id 167" for every WebM): -q leaves the one
    // summary line on stdout and on stderr only lines of ours ("defocus: warning: ...": these odd
    // frames warn that 4:2:0 chroma drops a row and a column), whatever the container.
    for (const std::string name : {"quiet.webm", "quiet.mp4", "quiet.mkv", "quiet.avi"}) {
        const Ran r = defocus(clip + " -y -o '" + file(name).string() + "'");
        EXPECT_EQ(r.exitCode, 0) << name << "\n" << r.err;
        std::istringstream err(r.err);
        for (std::string line; std::getline(err, line);)
            EXPECT_EQ(line.rfind("defocus: ", 0), 0u) << name << ": a line on stderr that is not ours: " << line;
        EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << name << ": stdout\n" << r.out;
    }
}

// --- the program itself ------------------------------------------------------------------------

// Defect: --info needing an input, or printing nothing useful.
TEST_F(CliFlags, InfoPrintsThePlatformAndExits)
{
    const Ran r = defocus("--info");
    EXPECT_EQ(r.exitCode, 0) << r.err;
    for (const char* line : {"EGL platform: ", "GL vendor:    ", "GL renderer:  ", "GL version:   4.", "GPU timers:   "})
        EXPECT_NE(r.out.find(line), std::string::npos) << line << " in\n" << r.out;
}

// Defect: --info not saying where depth prep runs or the presets' precision, or saying other
// than the renderer's choice: the CPU and 32f on a software renderer, the GPU and 16f on a GPU;
// DEFOCUS_DEPTH_PREP overriding it; the same for the passes' shaders (fragment on a software
// renderer, compute on a GPU) and DEFOCUS_PASSES.
TEST_F(CliFlags, InfoSaysWhereDepthPrepRunsAndThePresetsPrecision)
{
    const Ran r = defocus("--info");
    const bool software = softwareRenderer();
    EXPECT_NE(r.out.find(software ? "Depth prep:   CPU" : "Depth prep:   GPU"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(software ? "Precision:    32f" : "Precision:    16f"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(software ? "Passes:       fragment" : "Passes:       compute"), std::string::npos) << r.out;
    ::setenv("DEFOCUS_DEPTH_PREP", software ? "gpu" : "cpu", 1);
    ::setenv("DEFOCUS_PASSES", software ? "compute" : "fragment", 1);
    const Ran chosen = defocus("--info");
    ::unsetenv("DEFOCUS_DEPTH_PREP");
    ::unsetenv("DEFOCUS_PASSES");
    EXPECT_NE(chosen.out.find(software ? "Depth prep:   GPU" : "Depth prep:   CPU"), std::string::npos) << chosen.out;
    EXPECT_NE(chosen.out.find(software ? "Passes:       compute" : "Passes:       fragment"), std::string::npos)
        << chosen.out;
}

// Defects caught: reading threads counted from the machine's CPUs, not the process's (a Slurm job
// or taskset given one CPU of many would decode on threads it may not run), or --read-threads
// not what --info says a run reads with.
TEST_F(CliFlags, InfoSaysHowManyThreadsReadAndWriteOnTheCpusThisProcessMayUse)
{
    cpu_set_t mine;
    CPU_ZERO(&mine);
    ASSERT_EQ(sched_getaffinity(0, sizeof mine, &mine), 0);
    const int cpus = CPU_COUNT(&mine);
    const int expected = std::clamp(cpus - 1, 1, 8);
    const Ran r = defocus("--info");
    EXPECT_NE(r.out.find(fmt::format("Reading:      {} thread{} ahead of the filter ({} CPU{} this process may use)",
                                     expected, expected == 1 ? "" : "s", cpus, cpus == 1 ? "" : "s")),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find(fmt::format("Writing:      {} thread{} encoding a folder output's frames", expected,
                                     expected == 1 ? "" : "s")),
              std::string::npos)
        << r.out;
    EXPECT_NE(defocus("--info --read-threads 5").out.find("Reading:      5 threads"), std::string::npos);
    EXPECT_NE(defocus("--info --write-threads 6").out.find("Writing:      6 threads"), std::string::npos);
    // One CPU of this process's (taskset, as a scheduler pins a job).
    int first = 0;
    while (!CPU_ISSET(first, &mine))
        ++first;
    const fs::path out = file("info_one_cpu.txt");
    ASSERT_EQ(std::system(fmt::format("taskset -c {} '{}/defocus' --info >'{}' 2>&1", first, DEFOCUS_BINARY_DIR,
                                      out.string())
                              .c_str()),
              0);
    EXPECT_NE(readText(out).find("Reading:      1 thread ahead of the filter (1 CPU this process may use)"),
              std::string::npos)
        << readText(out);
}

// Defects: -q printing the log, -v not adding the debug lines, --version not the version.
TEST_F(CliFlags, QuietVerboseAndVersion)
{
    const std::string args = fmt::format("'{}' --depth '{}' --focus 1 -y -o '{}'", file("colour.png").string(),
                                         file("far.png").string(), file("logged.png").string());
    const Ran plain = defocus(args), quiet = defocus(args + " -q"), verbose = defocus(args + " -v");
    EXPECT_NE((plain.err + plain.out).find("info:"), std::string::npos) << plain.err;
    EXPECT_EQ((quiet.err + quiet.out).find("info:"), std::string::npos) << quiet.err;
    EXPECT_NE(quiet.out.find("1 frames in, 1 frames out"), std::string::npos) << quiet.out;
    EXPECT_NE((verbose.err + verbose.out).find("debug:"), std::string::npos) << verbose.err;
    const Ran version = defocus("--version");
    EXPECT_EQ(version.exitCode, 0);
    EXPECT_EQ(version.out, "defocus " DEFOCUS_VERSION "\n");
}

// Defects caught: --read-threads not reaching the reading (the debug line names the threads it
// read on), frames decoded side by side written in another order or changed, a value out of range
// taken.
TEST_F(CliFlags, ReadThreadsDecodeAheadAndTheFramesStayAsTheyWere)
{
    expectThreadsLeaveTheFilesAsTheyWere("--read-threads", "reading ahead on");
}

// Defects caught: --write-threads not reaching a folder output (the debug line names the threads
// it encodes on), frames encoded side by side written under other names, changed or listed in
// another order, a value out of range taken.
TEST_F(CliFlags, WriteThreadsEncodeAFoldersFramesAndTheFilesStayAsTheyWere)
{
    expectThreadsLeaveTheFilesAsTheyWere("--write-threads", "encoding the frames on");
}

// Defect: an option added to the command line with no test through the binary. Every option
// --help lists is named here with the test that runs it; one missing from --help fails too.
// Defect: --report not written, written before the clip is done, or counting frames wrongly (a
// scheduler reading "report exists" as "clip done" would then skip a clip that was never done).
TEST_F(CliFlags, ReportIsWrittenWhenTheClipIsDone)
{
    const fs::path report = file("single.report.json");
    const std::string output = file("single_out").string() + "/"; // a folder of PNGs
    const Ran run = defocus(fmt::format("'{}' --depth '{}' -q -o '{}' --report '{}'", file("clip/rgb").string(),
                                        file("clip/depth").string(), output, report.string()));
    ASSERT_EQ(run.exitCode, 0) << run.err;
    ASSERT_TRUE(fs::exists(report)) << run.err;
    const auto json = nlohmann::json::parse(readText(report));
    EXPECT_EQ(json.value("status", ""), "done") << json.dump(2);
    EXPECT_EQ(json.value("frames_in", -1), 2) << json.dump(2);
    EXPECT_EQ(json.value("frames_out", -1), 2) << json.dump(2);
    EXPECT_EQ(json.value("exit_status", -1), 0) << json.dump(2);
}

// Defect: --report-dir ignored (reports beside the outputs), --in-flight 2 losing or repeating a
// clip, or --redo not doing a reported clip again (a rerun after a fix would keep the old output).
TEST_F(CliFlags, BatchReportDirInFlightAndRedo)
{
    const fs::path reports = file("batch_reports");
    const fs::path manifest = file("batch.tsv");
    {
        std::ofstream m(manifest);
        for (int i = 0; i < 3; ++i)
            m << file("clip/rgb").string() << "\t" << file("clip/depth").string() << "\t" << file(fmt::format("batch_out{}", i)).string() << "/\n";
    }
    const std::string batch = fmt::format("--batch '{}' --report-dir '{}' --in-flight 2 -q", manifest.string(),
                                          reports.string());
    const Ran first = defocus(batch);
    ASSERT_EQ(first.exitCode, 0) << first.err;
    int found = 0;
    for (const auto& e : fs::directory_iterator(reports)) {
        ++found;
        EXPECT_EQ(nlohmann::json::parse(readText(e.path())).value("frames_out", -1), 2) << e.path();
    }
    EXPECT_EQ(found, 3);
    for (int i = 0; i < 3; ++i) {
        EXPECT_FALSE(fs::exists(file(fmt::format("batch_out{}.report.json", i)))) << "--report-dir ignored";
        EXPECT_TRUE(fs::is_directory(file(fmt::format("batch_out{}", i))));
    }
    // A frame removed by hand: a rerun skips the reported clip, --redo writes it again.
    const fs::path frame = file("batch_out0") / "0.png";
    ASSERT_TRUE(fs::remove(frame)) << frame << " was not written";
    const Ran skipped = defocus(batch);
    EXPECT_EQ(skipped.exitCode, 0) << skipped.err;
    EXPECT_FALSE(fs::exists(frame)) << "a reported clip was done again without --redo";
    const Ran redone = defocus(batch + " --redo");
    EXPECT_EQ(redone.exitCode, 0) << redone.err;
    EXPECT_TRUE(fs::exists(frame)) << "--redo did not do the reported clip again";

    // Defect: a clip whose report is missing (a killed run) refused for its existing output as a
    // single run without -y is, so that resubmitting never finishes it. Without its report the
    // batch does the clip again and replaces its output, with no -y (README, Many clips).
    for (const auto& e : fs::directory_iterator(reports))
        fs::remove(e.path());
    ASSERT_TRUE(fs::remove(frame));
    const Ran again = defocus(batch);
    EXPECT_EQ(again.exitCode, 0) << again.err;
    EXPECT_TRUE(fs::exists(frame)) << "a clip without a report was not done again";
    EXPECT_EQ(std::distance(fs::directory_iterator(reports), fs::directory_iterator{}), 3);
}

// Defect: a camera option that no longer parses its documented form, or accepts a malformed one
// silently. What they do to a camera is checked only where a camera exists (the v4l2 VM test runs
// the command line on vivid); here, without one, the parse is what can be held.
TEST_F(CliFlags, CameraOptionsParseTheirDocumentedForms)
{
    for (const std::string bad : {"--size 640", "--size 0x480", "--camera-fps 0", "--camera-fps -5"}) {
        const Ran run = defocus(fmt::format("'{}' --depth '{}' -o '{}' {}", file("colour.png").string(),
                                            file("far.png").string(), file("cam.png").string(), bad));
        EXPECT_EQ(run.exitCode, 2) << bad << "\n" << run.err;
        EXPECT_NE(run.err.find(bad.substr(0, bad.find(' '))), std::string::npos) << bad << ": " << run.err;
    }
    const Ran good = defocus(fmt::format("'{}' --depth '{}' -o '{}' -y -q --size 320x240 --camera-fps 15 --pixel-format YUYV",
                                         file("colour.png").string(), file("far.png").string(),
                                         file("cam.png").string()));
    EXPECT_EQ(good.exitCode, 0) << good.err;
}

/// Each option of a program's --help: its first --name -> the whole entry (names, type, default
/// and help text), white space folded.
std::map<std::string, std::string> helpEntries(const std::string& help)
{
    std::map<std::string, std::string> entries;
    std::string current;
    std::istringstream lines(help);
    for (std::string line; std::getline(lines, line);) {
        const auto text = line.find_first_not_of(' ');
        if (text == std::string::npos)
            continue;
        if (line[text] == '-' && text < 6) { // an option's first line; its help may follow on the next
            const std::string names = line.substr(text, line.find(' ', text) - text);
            std::smatch name;
            if (!std::regex_search(names, name, std::regex(R"(--[a-z][a-z0-9-]*)")))
                continue;
            current = name[0];
        } else if (current.empty()) {
            continue;
        }
        std::istringstream words(line);
        for (std::string word; words >> word;)
            entries[current] += (entries[current].empty() ? "" : " ") + word;
    }
    return entries;
}

std::string helpOf(const std::string& program)
{
    const fs::path out = fs::path(DEFOCUS_BINARY_DIR) / "test-scratch" / fmt::format("{}-{}.help", program, ::getpid());
    fs::create_directories(out.parent_path());
    const int status = std::system(fmt::format("'{}/{}' --help >'{}'", DEFOCUS_BINARY_DIR, program, out.string()).c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << program << " --help";
    std::string text = readText(out);
    fs::remove(out);
    return text;
}

// Defect: the lens, quality, depth-scale or camera options of defocus-preview or defocus-bench
// drift from defocus's: a default, a range, a choice or a help text changed in one program only
// (a second declaration edited), or an option one of them lacks. Every program declares them
// through samples/CliOptions.hpp, so each --help entry must be defocus's word for word. --near
// and --far differ on purpose (the preview's range follows its moving focus): each program's
// help must say so, and the preview's must name defocus's defaults as they are.
TEST(CliVocabulary, PreviewAndBenchDeclareTheSharedOptionsAsDefocusDoes)
{
    const auto defocus = helpEntries(helpOf("defocus"));
    const auto preview = helpEntries(helpOf("defocus-preview"));
    const auto bench = helpEntries(helpOf("defocus-bench"));
    const std::vector<std::string> quality{"--quality",    "--samples",          "--hexagon",       "--precision",
                                           "--resolution", "--near-field",       "--highlight-sprites",
                                           "--highlight-gain"};
    std::vector<std::string> shared{"--depth-scale", "--f-number",   "--focal-length",   "--sensor-width",
                                    "--fov-from",    "--max-coc",    "--coc-model",      "--blade-rotation", "--blades", "--aperture-ratio",
                                    "--size",        "--camera-fps", "--pixel-format"};
    shared.insert(shared.end(), quality.begin(), quality.end());
    const auto same = [&](const std::map<std::string, std::string>& other, const std::string& program,
                          const std::vector<std::string>& names) {
        for (const auto& name : names) {
            ASSERT_TRUE(defocus.count(name)) << name << " is not in defocus --help";
            ASSERT_TRUE(other.count(name)) << name << " is in defocus --help but not in " << program << " --help";
            EXPECT_EQ(other.at(name), defocus.at(name)) << name << ": " << program << " declares it otherwise";
        }
    };
    same(preview, "defocus-preview", shared);
    same(bench, "defocus-bench", quality);

    const LensSettings defaults;
    for (const auto& [name, metres] : {std::pair{std::string("--near"), defaults.nearLimitM},
                                       std::pair{std::string("--far"), defaults.farLimitM}}) {
        ASSERT_TRUE(defocus.count(name) && preview.count(name)) << name;
        EXPECT_EQ(defocus.at(name).rfind(fmt::format("{} FLOAT={:g} ", name, metres), 0), 0u)
            << "defocus " << name << " no longer defaults to " << metres << " m: " << defocus.at(name);
        EXPECT_NE(defocus.at(name).find("defocus-preview's follows its focus"), std::string::npos)
            << "defocus --help does not say the preview's " << name << " differs: " << defocus.at(name);
        EXPECT_NE(preview.at(name).find(fmt::format("defocus's stays at {:g} m", metres)), std::string::npos)
            << "defocus-preview --help does not name defocus's " << name << ": " << preview.at(name);
    }
}

TEST_F(CliFlags, EveryOptionInTheHelpHasATest)
{
    const std::map<std::string, std::string> tested{
        {"--help", "this test"},
        {"--version", "CliFlags.QuietVerboseAndVersion"},
        {"--output", "every test here (-o)"},
        {"--depth", "every test here; BadInputGLTest"},
        {"--depth-scale", "CliGLTest, LibraryGLTest.CommandLineAndLibraryGiveTheSamePicture"},
        {"--focus", "every test here; LibraryGLTest (auto)"},
        {"--f-number", "CliFlags.CocModelFocalRangeIgnoresTheAperture; SyntheticSceneGLTest"},
        {"--focal-length", "CliFlags.FocalLengthLongerLensBlursMore"},
        {"--sensor-width", "CliFlags.SensorWidthSmallerSensorBlursMore"},
        {"--fov-from", "CliFlags.FovFromImageDistanceBlursMoreUnlessFocusedAtInfinity"},
        {"--max-coc", "CliFlags.MaxCocClampsTheBlur"},
        {"--coc-model", "CliFlags.CocModelFocalRangeIgnoresTheAperture"},
        {"--near", "CliFlags.NearMovesOnlyTheNearBlur"},
        {"--far", "CliFlags.FarMovesOnlyTheFarBlur"},
        {"--quality", "CliFlags.QualityPresetsAndTheOptionsThatOverrideThem"},
        {"--samples", "CliFlags.SamplesSetTheTapsPerLine"},
        {"--hexagon", "CliFlags.HexagonRhombiKeepALightsEnergyAndMcIntoshsMinimumDoesNot"},
        {"--blade-rotation", "CliFlags.BladeRotationPutsACornerOrAnEdgeOnTop"},
        {"--blades", "CliFlags.BladesAndApertureRatioShapeTheLights"},
        {"--aperture-ratio", "CliFlags.BladesAndApertureRatioShapeTheLights; CliFlags.ApertureRatioSqueezesTheGather"},
        {"--precision", "CliFlags.PrecisionSetsTheTargetFormat"},
        {"--resolution", "CliFlags.ResolutionHalfKeepsTheSizeAndTheInFocusPixels"},
        {"--view", "CliFlags.ViewWritesEachStage"},
        {"--contact-sheet", "CliFlags.ContactSheetOfTheChosenFrameAndAnErrorBeyondTheClip"},
        {"--contact-frame", "CliFlags.ContactSheetOfTheChosenFrameAndAnErrorBeyondTheClip"},
        {"--frames", "SyntheticSceneGLTest (--demo --frames 3)"},
        {"--start", "CliGLTest StartEveryAndKeyedFocusPerFrame"},
        {"--every", "CliGLTest StartEveryAndKeyedFocusPerFrame"},
        {"--focus-point", "CliFlags.FocusPointMeasuresTheFocusThere"},
        {"--tau", "CliFlags.TauDampsTheTrackedFocus"},
        {"--overwrite", "exit-status-test.sh (existing output with and without -y)"},
        {"--keep-partial", "BadInputGLTest.BrokenFrameMidClipWithKeepPartialKeepsTheFramesBeforeIt; CliGLTest Interrupt"},
        {"--codec", "CliFlags.CodecAndImageFormatChooseWhatIsWritten"},
        {"--image-format", "CliFlags.CodecAndImageFormatChooseWhatIsWritten"},
        {"--fps", "CliFlags.FpsSetsTheVideosRate"},
        {"--timings", "CliFlags.TimingsWritesEveryFrameAndTheSummary"},
        {"--explain", "CliFlags.ExplainPrintsThePlanOfEachFrame"},
        {"--highlight-gain", "CliFlags.HighlightGainMakesClippedLightsBloom"},
        {"--near-field", "CliFlags.NearFieldSpreadsTheForegroundOverWhatIsBehind"},
        {"--no-near-field", "CliFlags.NearFieldSpreadsTheForegroundOverWhatIsBehind"},
        {"--highlight-sprites", "CliFlags.HighlightSpritesScatterLightsAboveWhite"},
        {"--no-highlight-sprites", "CliFlags.HighlightSpritesScatterLightsAboveWhite"},
        {"--always-on", "CliFlags.AlwaysOnRunsEveryPassWithTheSameResult"},
        {"--info", "CliFlags.InfoPrintsThePlatformAndExits"},
        {"--demo", "SyntheticSceneGLTest (the demo's frames are blurred)"},
        {"--demo-scene", "SyntheticSceneGLTest (--demo-scene edges)"},
        {"--quiet", "CliFlags.QuietVerboseAndVersion"},
        {"--verbose", "CliFlags.QuietVerboseAndVersion"},
        {"--size", "CliFlags.CameraOptionsParseTheirDocumentedForms"},
        {"--camera-fps", "CliFlags.CameraOptionsParseTheirDocumentedForms"},
        {"--pixel-format", "CliFlags.CameraOptionsParseTheirDocumentedForms"},
        {"--egl-device", "EglContextGLTest; EglDevicesTest"},
        {"--report", "CliFlags.ReportIsWrittenWhenTheClipIsDone"},
        {"--batch", "CliFlags.BatchReportDirInFlightAndRedo; batch-test.sh; slurm-test.sh"},
        {"--shard", "BatchTest; batch-test.sh (two shards through GNU parallel)"},
        {"--redo", "CliFlags.BatchReportDirInFlightAndRedo"},
        {"--report-dir", "CliFlags.BatchReportDirInFlightAndRedo"},
        {"--in-flight", "CliFlags.BatchReportDirInFlightAndRedo"},
        {"--read-threads", "CliFlags.ReadThreadsDecodeAheadAndTheFramesStayAsTheyWere"},
        {"--write-threads", "CliFlags.WriteThreadsEncodeAFoldersFramesAndTheFilesStayAsTheyWere"},
        {"--progress-interval", "exit-status-test.sh (progress lines in a log)"},
    };
    const Ran help = defocus("--help");
    ASSERT_EQ(help.exitCode, 0);
    std::set<std::string> listed;
    const std::regex option(R"((^|[ ,])(--[a-z][a-z0-9-]*))");
    std::istringstream lines(help.out);
    for (std::string line; std::getline(lines, line);) {
        // Option names start the line; later --names are in the description.
        const auto text = line.find_first_not_of(' ');
        if (text == std::string::npos || line[text] != '-')
            continue;
        const std::string names = line.substr(text, line.find(' ', text) - text);
        for (auto it = std::sregex_iterator(names.begin(), names.end(), option); it != std::sregex_iterator(); ++it)
            listed.insert((*it)[2]);
    }
    EXPECT_GT(listed.size(), 30u) << help.out;
    for (const auto& name : listed)
        EXPECT_TRUE(tested.count(name)) << name << " is in --help but has no test through the binary";
    for (const auto& [name, where] : tested)
        EXPECT_TRUE(listed.count(name)) << name << " (" << where << ") is no longer in --help";
}

} // namespace
} // namespace defocus
