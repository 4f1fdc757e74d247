// SPDX-License-Identifier: LGPL-2.1-or-later
// Several EGL contexts in one process: each lives and ends on its own.
#include <optional>

#include <epoxy/gl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "filter/Pipeline.hpp"
#include "filter/gl/EglContext.hpp"
#include "filter/gl/Objects.hpp"
#include "tests/GLTestSupport.hpp"

namespace defocus {
namespace {

using EglContexts = test::GLTest;

// Defect caught: a context's end terminating the EGL display that every context of the process
// shares (EGL displays are one per device), so that a second filter, or the library beside a
// GStreamer element, renders garbage or fails once the first is gone.
TEST_F(EglContexts, OneEndingLeavesTheOthersWorking)
{
    auto other = std::make_unique<gl::EglContext>(gl::EglContext::create());
    other.reset();
    context()->makeCurrent();
    ASSERT_TRUE(context()->isCurrent());
    cv::Mat color(48, 64, CV_8UC3, cv::Scalar(10, 120, 240)), depth(48, 64, CV_32F, cv::Scalar(2.0f));
    Pipeline pipeline;
    LensSettings lens;
    lens.focusM = 2.0;
    const cv::Mat out = pipeline.run({color, depth, 0.0, 0, "flat"}, lens, QualitySettings{});
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    cv::Mat diff;
    cv::absdiff(out, color, diff);
    EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0) << "an in-focus flat frame comes back as it went in";
}

// Defect caught: a context that ends unbinding another one that is current on the same thread.
TEST_F(EglContexts, EndingOneKeepsTheCurrentOneCurrent)
{
    auto other = std::make_unique<gl::EglContext>(gl::EglContext::create());
    context()->makeCurrent();
    other.reset();
    EXPECT_TRUE(context()->isCurrent());
}

// Defect: --egl-device N ignored (the context made on whatever device comes first), or a device
// that does not exist answered with another device instead of an error naming the devices.
TEST_F(EglContexts, AnAskedForDeviceIsUsedOrRefused)
{
    const auto devices = gl::EglContext::devices();
    gl::ContextOptions options;
    options.device = static_cast<int>(devices.size());
    try {
        gl::EglContext::create(options);
        ADD_FAILURE() << "EGL device " << devices.size() << " of " << devices.size() << " gave a context";
    } catch (const gl::ContextError& error) {
        EXPECT_NE(std::string(error.what()).find(fmt::format("there is no EGL device {}", devices.size())),
                  std::string::npos)
            << error.what();
    }
    if (devices.empty())
        GTEST_SKIP() << "this EGL lists no devices";
    const int last = static_cast<int>(devices.size()) - 1;
    options.device = last;
    std::optional<gl::EglContext> other;
    try {
        other.emplace(gl::EglContext::create(options));
    } catch (const gl::ContextError& error) {
        GTEST_SKIP() << "EGL device " << last << " gives no GL 4.5 context here: " << error.what();
    }
    EXPECT_EQ(other->info().device, last);
    EXPECT_EQ(other->info().platform.rfind("device", 0), 0u) << other->info().platform;
    other.reset();
    context()->makeCurrent();
}

// The bench reports the calling thread's CPU time in fence waits apart from its work: a driver
// that spins while it waits (NVIDIA's) charges the wait to the thread. Defects caught: a wait in
// waitAndDelete() not counted (or a null fence, which waits for nothing, counted), and the CPU
// time spent in a wait's scope not added (the scope measured around a busy loop of 5 ms of CPU).
TEST_F(EglContexts, FenceWaitsAreCountedWithTheCpuTimeTheyTake)
{
    gl::FenceWaits busy;
    {
        const gl::FenceWaitScope scope(busy);
        const double start = gl::threadCpuMs();
        volatile double sink = 0.0;
        while (gl::threadCpuMs() - start < 5.0)
            sink = sink + 1.0;
    }
    EXPECT_EQ(busy.count, 1);
    EXPECT_GE(busy.cpuMs, 5.0);
    EXPECT_LT(busy.cpuMs, 5000.0);

    const gl::FenceWaits before = gl::fenceWaits();
    GLsync none = nullptr;
    gl::waitAndDelete(none);
    EXPECT_EQ(gl::fenceWaits().count, before.count) << "a null fence waits for nothing";
    glClearColor(0.5f, 0.5f, 0.5f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    ASSERT_NE(fence, nullptr);
    gl::waitAndDelete(fence);
    EXPECT_EQ(fence, nullptr);
    const gl::FenceWaits after = gl::fenceWaits();
    EXPECT_EQ(after.count, before.count + 1);
    EXPECT_GE(after.cpuMs, before.cpuMs);
}

} // namespace
} // namespace defocus
