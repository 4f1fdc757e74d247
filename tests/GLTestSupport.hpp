// SPDX-License-Identifier: LGPL-2.1-or-later
// Fixture for tests that render: one headless EGL context per test program. Tests skip only
// when no EGL platform at all gives a context; llvmpipe is enough for every GL test.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "filter/gl/EglContext.hpp"

namespace defocus::test {

class GLTest : public ::testing::Test {
protected:
    static void SetUpTestSuite()
    {
        if (context() || !skipReason().empty())
            return;
        try {
            context() = std::make_unique<gl::EglContext>(gl::EglContext::create());
        } catch (const gl::ContextError& error) {
            skipReason() = error.what();
        }
    }
    void SetUp() override
    {
        if (!context())
            GTEST_SKIP() << "no EGL context: " << skipReason();
    }
    static std::unique_ptr<gl::EglContext>& context()
    {
        static std::unique_ptr<gl::EglContext> instance;
        return instance;
    }
    static std::string& skipReason()
    {
        static std::string reason;
        return reason;
    }
};

} // namespace defocus::test
