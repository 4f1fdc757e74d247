// SPDX-License-Identifier: LGPL-2.1-or-later
// libdefocus' messages (include/defocus/Log.hpp): never on standard output, which belongs to the
// program (`gst-launch-1.0 -q ... ! fdsink` writes video there); by default one line each on
// standard error; to a handler when one is set, from the level it asks for.
#include <cstdio>
#include <fcntl.h>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

#include <defocus/Log.hpp>
#include <defocus/Source.hpp>
#include <gtest/gtest.h>

namespace {

/// What `f` wrote to file descriptors 1 and 2.
template <class F>
std::pair<std::string, std::string> captureOutput(F f)
{
    std::fflush(stdout);
    std::fflush(stderr);
    char outName[] = "/tmp/defocus-log-out-XXXXXX", errName[] = "/tmp/defocus-log-err-XXXXXX";
    const int out = mkstemp(outName), err = mkstemp(errName);
    const int savedOut = dup(1), savedErr = dup(2);
    dup2(out, 1);
    dup2(err, 2);
    f();
    std::fflush(stdout);
    std::fflush(stderr);
    dup2(savedOut, 1);
    dup2(savedErr, 2);
    close(savedOut);
    close(savedErr);
    const auto read = [](int fd) {
        std::string text;
        lseek(fd, 0, SEEK_SET);
        char buffer[4096];
        for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;)
            text.append(buffer, static_cast<std::size_t>(n));
        close(fd);
        return text;
    };
    std::pair<std::string, std::string> result{read(out), read(err)};
    unlink(outName);
    unlink(errName);
    return result;
}

const std::string kImage = "rgb/1305031250.261917.png";

/// Opens one colour image with no depth, which the library warns about (it passes in focus).
void openImageWithoutDepth()
{
    defocus::SourceSettings settings;
    settings.input = std::string(DEFOCUS_DATA_DIR) + "/tum_fr1_rpy/" + kImage;
    defocus::Source source(settings);
}

// Defect caught: the library logging through spdlog's default logger, which writes to standard
// output: the warning would be in `out` (and in a pipeline's video).
TEST(LibraryLog, DefaultIsOneLineOnStandardErrorNothingOnStandardOutput)
{
    defocus::setLogHandler({});
    const auto [out, err] = captureOutput(openImageWithoutDepth);
    EXPECT_EQ(out, "");
    EXPECT_NE(err.find("defocus: warning: "), std::string::npos) << err;
    EXPECT_NE(err.find(kImage), std::string::npos) << err;
}

// Defect caught: a handler that is not called (messages still printed), called for levels below
// the one asked for, or given the wrong level.
TEST(LibraryLog, HandlerTakesTheMessagesFromItsLevel)
{
    std::vector<std::pair<defocus::LogLevel, std::string>> got;
    defocus::setLogHandler([&got](defocus::LogLevel level, std::string_view m) { got.emplace_back(level, m); },
                           defocus::LogLevel::Warning);
    const auto [out, err] = captureOutput(openImageWithoutDepth);
    EXPECT_EQ(out, "");
    EXPECT_EQ(err, "");
    ASSERT_EQ(got.size(), 1u);
    EXPECT_EQ(got[0].first, defocus::LogLevel::Warning);
    EXPECT_NE(got[0].second.find(kImage), std::string::npos) << got[0].second;

    got.clear();
    defocus::setLogHandler([&got](defocus::LogLevel level, std::string_view m) { got.emplace_back(level, m); },
                           defocus::LogLevel::Error);
    captureOutput(openImageWithoutDepth);
    EXPECT_TRUE(got.empty()) << "a warning reached a handler that asked for errors only";
    defocus::setLogHandler({});
}

} // namespace
