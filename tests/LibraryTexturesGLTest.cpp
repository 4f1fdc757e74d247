// SPDX-License-Identifier: LGPL-2.1-or-later
// Filter::processTextures() on a context of the test's own (raw EGL, as GStreamer's GL library or
// an application makes one): the same bytes as Filter::process() of the same images, in either
// channel order and each depth format; the caller's GL state as it was; clear errors.
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include <defocus/defocus.hpp>
#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/ImageCompare.hpp"
#include "tests/TestSupport.hpp"

namespace {

namespace fs = std::filesystem;
using Order = defocus::GlFrame::Order;
using DepthFormat = defocus::GlFrame::DepthFormat;

/// An OpenGL 4.5 core context made and owned here, current on this thread, on the EGL display the
/// library renders on (defocus::eglDisplay(): an EGL device, else Mesa's surfaceless platform),
/// which stays initialised for the rest of the process.
struct CallerContext {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
    std::string why; ///< empty when made

    CallerContext()
    {
        try {
            display = static_cast<EGLDisplay>(defocus::eglDisplay());
        } catch (const defocus::GlError& error) {
            why = error.what();
            return;
        }
        const EGLint configAttributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLConfig config = nullptr;
        EGLint count = 0;
        eglBindAPI(EGL_OPENGL_API);
        eglChooseConfig(display, configAttributes, &config, 1, &count);
        const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                     EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
        context = eglCreateContext(display, count > 0 ? config : EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
        if (context == EGL_NO_CONTEXT || !eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
            why = "no OpenGL 4.5 core context";
    }
    ~CallerContext()
    {
        if (context != EGL_NO_CONTEXT) {
            eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            eglDestroyContext(display, context);
        }
    }
    void makeCurrent() const { eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context); }
};

/// A texture of the test's context, deleted at the end of the test.
struct Texture {
    GLuint id = 0;
    Texture(GLenum format, cv::Size size)
    {
        // Mutable storage, as GStreamer makes its textures; the binding is put back.
        GLint bound = 0;
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &bound);
        glGenTextures(1, &id);
        glBindTexture(GL_TEXTURE_2D, id);
        const GLenum base = format == GL_RGBA8 ? GL_RGBA : format == GL_RG8 ? GL_RG : GL_RED;
        const GLenum type = format == GL_R16 ? GL_UNSIGNED_SHORT : format == GL_R32F ? GL_FLOAT : GL_UNSIGNED_BYTE;
        glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(format), size.width, size.height, 0, base, type, nullptr);
        glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(bound));
    }
    ~Texture() { glDeleteTextures(1, &id); }
    Texture(const Texture&) = delete;
    Texture& operator=(const Texture&) = delete;
    void upload(GLenum format, GLenum type, const cv::Mat& image) const
    {
        CV_Assert(image.isContinuous());
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glTextureSubImage2D(id, 0, 0, 0, image.cols, image.rows, format, type, image.data);
    }
};

class LibraryTextures : public ::testing::Test {
protected:
    static void SetUpTestSuite()
    {
        try {
            own() = std::make_unique<defocus::Filter>(settings());
        } catch (const defocus::GlError& error) {
            skip() = error.what();
            return;
        }
        caller() = std::make_unique<CallerContext>();
        if (!caller()->why.empty())
            skip() = caller()->why;
    }
    static void TearDownTestSuite()
    {
        if (caller() && caller()->why.empty())
            caller()->makeCurrent();
        onCaller().reset(); // its GL objects go with the caller's context current
        caller().reset();
        own().reset();
    }
    void SetUp() override
    {
        if (!skip().empty())
            GTEST_SKIP() << skip();
        caller()->makeCurrent();
        if (!onCaller()) {
            defocus::ContextOptions options;
            options.callerContext = true;
            onCaller() = std::make_unique<defocus::Filter>(settings(), options);
        }
        std::ifstream list(defocus::test::dataDir() / "tum_fr1_rpy" / "associations.txt");
        std::string line;
        for (int i = 0; i < 9; ++i)
            std::getline(list, line);
        std::istringstream fields(line);
        std::string t1, rgb, t2, depth;
        fields >> t1 >> rgb >> t2 >> depth;
        const fs::path dir = defocus::test::dataDir() / "tum_fr1_rpy";
        color_ = cv::imread((dir / rgb).string(), cv::IMREAD_COLOR);
        depth_ = cv::imread((dir / depth).string(), cv::IMREAD_UNCHANGED);
        ASSERT_EQ(depth_.type(), CV_16UC1);
    }

    static defocus::Settings settings()
    {
        defocus::Settings s;
        s.depthScale = 5000;
        s.lens.focusM = 1.0;
        s.lens.fNumber = 1.4;
        return s;
    }
    static std::unique_ptr<defocus::Filter>& own()
    {
        static std::unique_ptr<defocus::Filter> instance;
        return instance;
    }
    static std::unique_ptr<defocus::Filter>& onCaller()
    {
        static std::unique_ptr<defocus::Filter> instance;
        return instance;
    }
    static std::unique_ptr<CallerContext>& caller()
    {
        static std::unique_ptr<CallerContext> instance;
        return instance;
    }
    static std::string& skip()
    {
        static std::string reason;
        return reason;
    }

    /// The frame through processTextures() on the caller's context (colour and output in the
    /// given orders, depth in `format`), read back as BGR.
    cv::Mat throughTextures(const defocus::Settings& s, Order in, Order out, DepthFormat format, double t = 0.0)
    {
        onCaller()->setSettings(s);
        const Texture color(GL_RGBA8, color_.size()), output(GL_RGBA8, color_.size());
        cv::Mat rgba;
        cv::cvtColor(color_, rgba, in == Order::Rgba ? cv::COLOR_BGR2RGBA : cv::COLOR_BGR2BGRA);
        color.upload(GL_RGBA, GL_UNSIGNED_BYTE, rgba);
        const GLenum depthFormat = format == DepthFormat::R16 ? GL_R16 : format == DepthFormat::Rg8Le ? GL_RG8 : GL_R32F;
        const Texture depth(depthFormat, depth_.size());
        if (format == DepthFormat::R32F) {
            cv::Mat metres;
            depth_.convertTo(metres, CV_32F, 1.0 / s.depthScale);
            depth.upload(GL_RED, GL_FLOAT, metres);
        } else if (format == DepthFormat::R16) {
            depth.upload(GL_RED, GL_UNSIGNED_SHORT, depth_);
        } else {
            cv::Mat bytes(depth_.size(), CV_8UC2); // little-endian: low byte first
            for (int y = 0; y < depth_.rows; ++y)
                for (int x = 0; x < depth_.cols; ++x) {
                    const auto units = depth_.at<std::uint16_t>(y, x);
                    bytes.at<cv::Vec2b>(y, x) = {static_cast<std::uint8_t>(units & 0xff),
                                                 static_cast<std::uint8_t>(units >> 8)};
                }
            depth.upload(GL_RG, GL_UNSIGNED_BYTE, bytes);
        }
        defocus::GlFrame frame;
        frame.color = color.id;
        frame.colorOrder = in;
        frame.depth = depth.id;
        frame.depthFormat = format;
        frame.output = output.id;
        frame.outputOrder = out;
        frame.width = color_.cols;
        frame.height = color_.rows;
        onCaller()->processTextures(frame, t);
        cv::Mat result(color_.size(), CV_8UC4);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glGetTextureImage(output.id, 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(result.total() * 4),
                          result.data);
        // Alpha is opaque everywhere.
        std::vector<cv::Mat> channels;
        cv::split(result, channels);
        EXPECT_EQ(cv::countNonZero(channels[3] != 255), 0) << "alpha not 1";
        cv::Mat bgr;
        cv::cvtColor(result, bgr, out == Order::Rgba ? cv::COLOR_RGBA2BGR : cv::COLOR_BGRA2BGR);
        return bgr;
    }
    /// The same frame through process() on a Filter with a context of its own.
    cv::Mat throughMats(const defocus::Settings& s, double t = 0.0)
    {
        own()->setSettings(s);
        return own()->process(color_, depth_, t);
    }

    cv::Mat color_, depth_;
};

using defocus::test::identical;

// Defects caught: red and blue swapped on the way in or out (the BGRA order GStreamer uses), the
// GRAY16_LE bytes read high byte first, R32F depth scaled as units, the output copy decoding
// sRGB (a GPU copy through a sampler of the sRGB target), alpha left as the target's. Both paths
// run the same passes on the same driver, so they must agree exactly.
TEST_F(LibraryTextures, SameBytesAsProcessInEachOrderAndDepthFormat)
{
    const defocus::Settings s = settings();
    const cv::Mat expected = throughMats(s);
    EXPECT_TRUE(identical(throughTextures(s, Order::Rgba, Order::Rgba, DepthFormat::R16), expected));
    EXPECT_TRUE(identical(throughTextures(s, Order::Bgra, Order::Bgra, DepthFormat::Rg8Le), expected));
    EXPECT_TRUE(identical(throughTextures(s, Order::Rgba, Order::Bgra, DepthFormat::R32F), expected));
    EXPECT_TRUE(identical(throughTextures(s, Order::Bgra, Order::Rgba, DepthFormat::R16), expected));
}

// Defects caught: a GPU path that only holds for the default preset (full size, McIntosh's
// kernel), or the CPU fallback (a frame all in focus, the depth view's legend) uploaded in the
// wrong order or not at all.
TEST_F(LibraryTextures, SameBytesForOtherPresetsViewsAndFramesInFocus)
{
    defocus::Settings s = settings();
    s.quality.preset = defocus::Quality::Preset::High;
    s.quality.hexagon = defocus::Quality::Hexagon::McIntosh;
    EXPECT_TRUE(identical(throughTextures(s, Order::Bgra, Order::Rgba, DepthFormat::R16), throughMats(s)));
    s = settings();
    s.view = defocus::Settings::View::Depth;
    EXPECT_TRUE(identical(throughTextures(s, Order::Bgra, Order::Bgra, DepthFormat::R16), throughMats(s)));
    s = settings();
    s.lens.fNumber = 64;
    s.lens.focalLengthMm = 1;
    EXPECT_TRUE(identical(throughTextures(s, Order::Rgba, Order::Bgra, DepthFormat::R16), throughMats(s)));
    EXPECT_TRUE(onCaller()->lastFrame().plan.allInFocus) << "the frame was meant to be all in focus";
}

// Defect caught: a GL binding or switch of the caller's left as the filter's (an sRGB switch left
// on brightens what GStreamer draws next; a sampler left bound overrides its textures' filtering;
// an image unit left on a target of the filter's, where the passes run as compute shaders:
// library_textures_gpu_defaults, a caller's compute shader would store into the filter's target).
TEST_F(LibraryTextures, LeavesTheCallersStateAsItWas)
{
    GLuint framebuffer = 0, sampler = 0, texture = 0;
    glCreateFramebuffers(1, &framebuffer);
    glCreateSamplers(1, &sampler);
    glCreateTextures(GL_TEXTURE_2D, 1, &texture);
    glTextureStorage2D(texture, 1, GL_RGBA8, 4, 4);
    glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R8);
    glBindImageTexture(1, texture, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA8);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, texture);
    glBindSampler(0, sampler);
    glDisable(GL_FRAMEBUFFER_SRGB);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_SCISSOR_TEST);
    glViewport(1, 2, 3, 4);
    const auto integer = [](GLenum name) {
        GLint value = -1;
        glGetIntegerv(name, &value);
        return value;
    };
    // With the scissor on too, the whole frame is filtered.
    EXPECT_TRUE(identical(throughTextures(settings(), Order::Rgba, Order::Rgba, DepthFormat::R16),
                          throughMats(settings())));
    EXPECT_EQ(integer(GL_DRAW_FRAMEBUFFER_BINDING), static_cast<GLint>(framebuffer));
    EXPECT_EQ(integer(GL_READ_FRAMEBUFFER_BINDING), static_cast<GLint>(framebuffer));
    EXPECT_EQ(integer(GL_ACTIVE_TEXTURE), GL_TEXTURE3);
    EXPECT_EQ(integer(GL_TEXTURE_BINDING_2D), static_cast<GLint>(texture));
    glActiveTexture(GL_TEXTURE0);
    EXPECT_EQ(integer(GL_SAMPLER_BINDING), static_cast<GLint>(sampler));
    EXPECT_EQ(integer(GL_TEXTURE_BINDING_2D), 0);
    EXPECT_FALSE(glIsEnabled(GL_FRAMEBUFFER_SRGB));
    EXPECT_TRUE(glIsEnabled(GL_BLEND));
    EXPECT_TRUE(glIsEnabled(GL_SCISSOR_TEST));
    EXPECT_EQ(integer(GL_BLEND_SRC_RGB), GL_SRC_ALPHA);
    EXPECT_EQ(integer(GL_BLEND_DST_RGB), GL_ONE_MINUS_SRC_ALPHA);
    GLint viewport[4] = {};
    glGetIntegerv(GL_VIEWPORT, viewport);
    EXPECT_EQ(cv::Vec4i(viewport[0], viewport[1], viewport[2], viewport[3]), cv::Vec4i(1, 2, 3, 4));
    EXPECT_EQ(integer(GL_CURRENT_PROGRAM), 0);
    EXPECT_EQ(integer(GL_VERTEX_ARRAY_BINDING), 0);
    const auto image = [](GLenum name, GLuint unit) {
        GLint value = -1;
        glGetIntegeri_v(name, unit, &value);
        return value;
    };
    EXPECT_EQ(image(GL_IMAGE_BINDING_NAME, 0), 0);
    EXPECT_EQ(image(GL_IMAGE_BINDING_NAME, 1), static_cast<GLint>(texture));
    EXPECT_EQ(image(GL_IMAGE_BINDING_ACCESS, 1), GL_READ_WRITE);
    EXPECT_EQ(image(GL_IMAGE_BINDING_FORMAT, 1), GL_RGBA8);
    glBindImageTexture(1, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R8);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindSampler(0, 0);
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteSamplers(1, &sampler);
    glDeleteTextures(1, &texture);
}

// Defects caught: a Filter meant for the caller's context made with none current (it would make
// GL calls into nothing), textures of another format taken as RGBA8 or R16, processTextures() on
// a Filter with a context of its own (whose textures are not the caller's).
TEST_F(LibraryTextures, ErrorsSayWhatIsWrong)
{
    defocus::ContextOptions options;
    options.callerContext = true;
    eglMakeCurrent(caller()->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    try {
        defocus::Filter none(settings(), options);
        ADD_FAILURE() << "made with no context current";
    } catch (const defocus::GlError& error) {
        EXPECT_NE(std::string(error.what()).find("no OpenGL context is current"), std::string::npos) << error.what();
    }
    caller()->makeCurrent();

    const Texture color(GL_RGBA16F, color_.size()), output(GL_RGBA8, color_.size()), depth(GL_R16, depth_.size());
    defocus::GlFrame frame;
    frame.color = color.id;
    frame.depth = depth.id;
    frame.output = output.id;
    frame.width = color_.cols;
    frame.height = color_.rows;
    try {
        onCaller()->processTextures(frame);
        ADD_FAILURE() << "an RGBA16F colour texture taken";
    } catch (const defocus::InputError& error) {
        EXPECT_NE(std::string(error.what()).find("colour texture"), std::string::npos) << error.what();
    }
    frame.color = output.id;
    frame.depthFormat = DepthFormat::R32F;
    try {
        onCaller()->processTextures(frame);
        ADD_FAILURE() << "an R16 depth texture taken as R32F";
    } catch (const defocus::InputError& error) {
        EXPECT_NE(std::string(error.what()).find("depth texture"), std::string::npos) << error.what();
    }
    EXPECT_THROW(own()->processTextures(frame), defocus::InputError);
}

} // namespace
