// libdefocus' public API (include/defocus/): its errors speak the command line's words, the
// command line's automatic focus, the live autofocus, and a Filter handed from thread to thread.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <defocus/defocus.hpp>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/TestSupport.hpp"

namespace {

namespace fs = std::filesystem;

struct Pair {
    fs::path color, depth;
};

/// Line `line` of the bundled clip's associations.
Pair bundled(int line)
{
    std::ifstream list(defocus::test::dataDir() / "tum_fr1_rpy" / "associations.txt");
    std::string text;
    for (int i = 0; i < line; ++i)
        std::getline(list, text);
    std::istringstream fields(text);
    std::string t1, rgb, t2, depth;
    fields >> t1 >> rgb >> t2 >> depth;
    const fs::path dir = defocus::test::dataDir() / "tum_fr1_rpy";
    return {dir / rgb, dir / depth};
}

::testing::AssertionResult identical(const cv::Mat& a, const cv::Mat& b)
{
    if (a.size() != b.size() || a.type() != b.type())
        return ::testing::AssertionFailure() << "sizes or types differ";
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    const int differing = cv::countNonZero(diff.reshape(1));
    return differing == 0 ? ::testing::AssertionSuccess()
                          : ::testing::AssertionFailure() << differing << " samples differ";
}

class Library : public ::testing::Test {
protected:
    void SetUp() override
    {
        const Pair pair = bundled(9);
        color_ = cv::imread(pair.color.string(), cv::IMREAD_COLOR);
        depth_ = cv::imread(pair.depth.string(), cv::IMREAD_UNCHANGED);
        settings_.depthScale = 5000;
        settings_.lens.focusM = 1.0;
        settings_.lens.fNumber = 1.4;
        try {
            filter_.emplace(settings_);
        } catch (const defocus::GlError& error) {
            GTEST_SKIP() << "no OpenGL 4.5: " << error.what();
        }
    }
    cv::Mat color_, depth_;
    defocus::Settings settings_;
    std::optional<defocus::Filter> filter_;
};

// Defect caught: settings out of range accepted, or refused with another message than the
// command line's (the element and the programs show these words to users).
TEST_F(Library, SettingsErrorsSpeakTheCommandLinesWords)
{
    defocus::Settings bad = settings_;
    bad.lens.fNumber = 0.5;
    try {
        filter_->setSettings(bad);
        FAIL() << "f/0.5 accepted";
    } catch (const defocus::SettingsError& error) {
        EXPECT_STREQ(error.what(), "--f-number 0.5 is outside [0.7, 64]");
    }
    EXPECT_EQ(filter_->settings().lens.fNumber, 1.4) << "a refused change must leave the settings as they were";
    bad = settings_;
    bad.quality.samples = 1;
    EXPECT_THROW(filter_->setSettings(bad), defocus::SettingsError);

    defocus::Settings clamped = bad;
    clamped.lens.focusM = 0.01;
    const auto issues = defocus::check(clamped, true);
    ASSERT_EQ(issues.size(), 2u);
    EXPECT_EQ(issues[0], "--focus 0.01 m must be farther than the focal length (0.05 m)");
    EXPECT_EQ(issues[1], "--samples 1 is outside [2, 64]");
    EXPECT_EQ(*clamped.quality.samples, 2);
    EXPECT_GT(clamped.lens.focusM, 0.05);
    EXPECT_TRUE(defocus::check(clamped).empty()) << "clamped settings are valid";
}

// Defect caught: images of the wrong type or shape filtered anyway (garbage, or an OpenCV
// assertion) instead of an InputError that says what was expected.
TEST_F(Library, InputErrorsNameTheImage)
{
    cv::Mat color16;
    color_.convertTo(color16, CV_16UC3);
    try {
        filter_->process(color16, depth_);
        FAIL() << "16-bit colour accepted";
    } catch (const defocus::InputError& error) {
        EXPECT_NE(std::string(error.what()).find("colour image is 16-bit, 3 channels"), std::string::npos)
            << error.what();
    }
    EXPECT_THROW(filter_->process(color_, cv::Mat(480, 480, CV_16UC1, cv::Scalar(5000))), defocus::InputError);
    EXPECT_THROW(filter_->process(color_, cv::Mat(480, 640, CV_8UC1, cv::Scalar(50))), defocus::InputError);
    // Half-size depth of the same aspect is resized, as the command line does.
    cv::Mat half;
    cv::resize(depth_, half, {320, 240}, 0, 0, cv::INTER_NEAREST);
    EXPECT_NO_THROW(filter_->process(color_, half));
}

// Defect caught: FirstFrame measuring focus otherwise than `defocus --focus auto` (another
// window, a mean instead of the median, measured again on later frames): the results differ.
TEST_F(Library, FirstFrameAutofocusIsTheCommandLinesAuto)
{
    const Pair pair = bundled(9);
    const fs::path out = defocus::test::scratchDir("library_auto") / "cli.png";
    const std::string command = std::string(DEFOCUS_BINARY_DIR) + "/defocus '" + pair.color.string() + "' --depth '" +
                                pair.depth.string() + "' --depth-scale 5000 --f-number 1.4 --focus auto -q -o '" +
                                out.string() + "' > /dev/null";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    defocus::Settings automatic = settings_;
    automatic.autofocus.mode = defocus::AutofocusOptions::Mode::FirstFrame;
    filter_->setSettings(automatic);
    EXPECT_TRUE(identical(filter_->process(color_, depth_), cv::imread(out.string(), cv::IMREAD_COLOR)));
    const double chosen = filter_->lastFrame().focusM;
    // Later frames keep the first frame's focus, whatever their depth.
    filter_->process(color_, cv::Mat(depth_.size(), CV_16UC1, cv::Scalar(20000)));
    EXPECT_EQ(filter_->lastFrame().focusM, chosen);
    filter_->reset();
    filter_->process(color_, cv::Mat(depth_.size(), CV_16UC1, cv::Scalar(20000)));
    EXPECT_NEAR(filter_->lastFrame().focusM, 4.0, 1e-6) << "reset() measures afresh";
}

// Defect caught: Follow not stepped by the frames' timestamps (no convergence, or a jump when
// the time constant asks for a glide).
TEST_F(Library, FollowGlidesToTheDepthOfTheCentre)
{
    defocus::Settings follow = settings_;
    follow.autofocus.mode = defocus::AutofocusOptions::Mode::Follow;
    follow.autofocus.timeConstantS = 0.25;
    filter_->setSettings(follow);
    const cv::Mat near(depth_.size(), CV_16UC1, cv::Scalar(5000)), far(depth_.size(), CV_16UC1, cv::Scalar(15000));
    filter_->process(color_, near, 1.0);
    EXPECT_NEAR(filter_->lastFrame().focusM, 1.0, 1e-6) << "the first measurement is taken at once";
    filter_->process(color_, far, 1.0 + 1.0 / 30);
    const double after = filter_->lastFrame().focusM;
    EXPECT_GT(after, 1.0);
    EXPECT_LT(after, 1.5) << "one frame of a 0.25 s spring moves a little of the way";
    for (int i = 2; i < 120; ++i)
        filter_->process(color_, far, 1.0 + i / 30.0);
    EXPECT_NEAR(filter_->lastFrame().focusM, 3.0, 0.01) << "4 s = 16 time constants: there";
}

// Defect caught: a Filter that only works on the thread that made it (its context left current
// there, or not made current on the caller): the second thread's result is wrong or it throws.
TEST_F(Library, HandedToAnotherThreadAfterRelease)
{
    const cv::Mat here = filter_->process(color_, depth_);
    filter_->release();
    cv::Mat there;
    std::string error;
    std::thread other([&] {
        try {
            there = filter_->process(color_, depth_);
            filter_->release();
        } catch (const std::exception& e) {
            error = e.what();
        }
    });
    other.join();
    ASSERT_EQ(error, "");
    EXPECT_TRUE(identical(here, there));
    EXPECT_TRUE(identical(filter_->process(color_, depth_), here)) << "and back on this thread";
}

} // namespace
