// Pipeline: owns the targets, runs the passes in order, reads results back, times everything.
#include "filter/Pipeline.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>

#include <epoxy/gl.h>

#include "filter/DepthPrep.hpp"
#include "filter/Lens.hpp"
#include "filter/Views.hpp"
#include "filter/gl/GpuTimer.hpp"
#include "filter/gl/Objects.hpp"
#include "filter/passes/CocPass.hpp"
#include "filter/passes/CompositePass.hpp"
#include "filter/passes/HexBlurPass.hpp"
#include "filter/passes/ViewPass.hpp"

namespace defocus {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// A texture and the framebuffer that renders into it.
struct Target {
    gl::Texture texture;
    gl::Framebuffer framebuffer;

    void ensure(GLenum format, cv::Size size, const char* name)
    {
        if (texture && texture.format() == format && texture.width() == size.width &&
            texture.height() == size.height)
            return;
        framebuffer = {};
        texture = gl::Texture(format, size.width, size.height, name);
        framebuffer = gl::Framebuffer(texture, name);
    }
};

void ensureTexture(gl::Texture& texture, GLenum format, cv::Size size, const char* name)
{
    if (!texture || texture.format() != format || texture.width() != size.width || texture.height() != size.height)
        texture = gl::Texture(format, size.width, size.height, name);
}

} // namespace

struct Pipeline::Impl {
    gl::VertexArray vao = gl::VertexArray::create();
    CocPass cocPass;
    HexBlurPass hexBlurPass;
    CompositePass compositePass;
    ViewPass viewPass;
    gl::GpuTimer timer;

    gl::Texture color;
    gl::Texture depth;
    Target coc, horizontal, diagonalA, diagonalB, outSrgb, outLinear;

    cv::Size size;
    PreparedDepth prepared;
    float maxCocPx = 0.0f;
    FrameTimings timings;
    Clock::time_point frameStart;

    explicit Impl(bool timers) : timer(timers) {}

    const Target& target(View view) const
    {
        switch (view) {
        case View::Input: return coc;
        case View::Horizontal: return horizontal;
        case View::DiagonalA: return diagonalA;
        case View::DiagonalB: return diagonalB;
        default: assert(false && "not an intermediate target"); return coc;
        }
    }
};

Pipeline::Pipeline(bool timers)
{
    GLint bits = 0;
    glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
    impl_ = std::make_unique<Impl>(timers && bits > 0);
    // Only sRGB-format attachments are affected: those get linear -> sRGB encoding on write.
    glEnable(GL_FRAMEBUFFER_SRGB);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
}

Pipeline::~Pipeline() = default;

void Pipeline::process(const Frame& frame, const LensSettings& lens, const QualitySettings& quality)
{
    Impl& p = *impl_;
    CV_Assert(!frame.color.empty() && (frame.color.type() == CV_8UC3 || frame.color.type() == CV_32FC3));
    p.timings = {};
    p.frameStart = Clock::now();
    p.size = frame.color.size();

    // Depth: colour-sized, holes filled. With no depth at all, everything sits on the focus plane.
    auto start = Clock::now();
    const float fallback = std::isinf(lens.focusM) ? 1e6f : static_cast<float>(lens.focusM);
    p.prepared = prepareDepth(frame.depth, p.size, fallback);
    p.timings.depthPrepMs = msSince(start);

    start = Clock::now();
    const bool srgbInput = frame.color.type() == CV_8UC3;
    ensureTexture(p.color, srgbInput ? GL_SRGB8 : GL_RGB32F, p.size, "input colour");
    CV_Assert(frame.color.isContinuous() && p.prepared.metres.isContinuous());
    p.color.upload(GL_BGR, srgbInput ? GL_UNSIGNED_BYTE : GL_FLOAT, frame.color.data);
    ensureTexture(p.depth, GL_R32F, p.size, "filled depth");
    p.depth.upload(GL_RED, GL_FLOAT, p.prepared.metres.data);
    p.timings.uploadMs = msSince(start);

    start = Clock::now();
    const bool half = quality.targetFormat == TargetFormat::Rgba16F;
    const GLenum format = half ? GL_RGBA16F : GL_RGBA32F;
    p.coc.ensure(format, p.size, "coc");
    p.horizontal.ensure(format, p.size, "horizontal");
    p.diagonalA.ensure(format, p.size, "diagonal A");
    p.diagonalB.ensure(format, p.size, "diagonal B");

    const CocCoefficients k = cocCoefficients(lens, p.size.width);
    p.maxCocPx = k.maxCocPx;
    glBindVertexArray(p.vao.id());
    p.timer.begin(CocPass::kName);
    p.cocPass.run(p.color, p.depth, k, half, p.coc.framebuffer);
    p.timer.end();
    p.timer.begin("horizontal");
    p.hexBlurPass.run(p.coc.texture, p.depth, 0.0f, quality.samples, p.horizontal.framebuffer);
    p.timer.end();
    p.timer.begin("diagonal-a");
    p.hexBlurPass.run(p.horizontal.texture, p.depth, 120.0f, quality.samples, p.diagonalA.framebuffer);
    p.timer.end();
    p.timer.begin("diagonal-b");
    p.hexBlurPass.run(p.horizontal.texture, p.depth, -120.0f, quality.samples, p.diagonalB.framebuffer);
    p.timer.end();
    p.timings.renderMs = msSince(start);
}

cv::Mat Pipeline::read(View view, Encoding encoding)
{
    Impl& p = *impl_;
    CV_Assert(!p.size.empty());
    const auto start = Clock::now();
    Target& out = encoding == Encoding::Srgb8 ? p.outSrgb : p.outLinear;
    out.ensure(encoding == Encoding::Srgb8 ? GL_SRGB8_ALPHA8 : GL_RGBA32F, p.size,
               encoding == Encoding::Srgb8 ? "output sRGB" : "output linear");

    glBindVertexArray(p.vao.id());
    float low = 0.0f, high = 0.0f;
    if (view == View::Composite) {
        p.timer.begin(CompositePass::kName);
        p.compositePass.run(p.diagonalA.texture, p.diagonalB.texture, out.framebuffer);
    } else {
        p.timer.begin(ViewPass::kName);
        if (view == View::Depth) {
            double lo = 0.0, hi = 0.0;
            cv::minMaxLoc(p.prepared.metres, &lo, &hi);
            low = static_cast<float>(std::max(lo, 1e-3));
            high = static_cast<float>(std::max(hi, lo * 1.01 + 1e-3));
            p.viewPass.run(p.depth, ViewPass::Mode::Depth, low, high, out.framebuffer);
        } else if (view == View::Coc) {
            high = p.maxCocPx;
            p.viewPass.run(p.coc.texture, ViewPass::Mode::Coc, 0.0f, high, out.framebuffer);
        } else {
            p.viewPass.run(p.target(view).texture, ViewPass::Mode::Color, 0.0f, 0.0f, out.framebuffer);
        }
    }
    p.timer.end();

    cv::Mat image(p.size, encoding == Encoding::Srgb8 ? CV_8UC3 : CV_32FC3);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, out.framebuffer.id());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, p.size.width, p.size.height, GL_BGR,
                 encoding == Encoding::Srgb8 ? GL_UNSIGNED_BYTE : GL_FLOAT, image.data);
    p.timings.readbackMs = msSince(start);

    for (auto& [name, ms] : p.timer.collect())
        p.timings.gpu.push_back({name, ms});
    p.timings.totalMs = msSince(p.frameStart);

    if (view == View::Depth)
        drawLegend(image, LegendKind::DepthMetres, low, high);
    else if (view == View::Coc)
        drawLegend(image, LegendKind::SignedCocPixels, -high, high);
    return image;
}

cv::Mat Pipeline::run(const Frame& frame, const LensSettings& lens, const QualitySettings& quality, View view,
                      Encoding encoding)
{
    process(frame, lens, quality);
    return read(view, encoding);
}

cv::Mat Pipeline::readTarget(View view) const
{
    const Target& target = impl_->target(view);
    cv::Mat image(impl_->size, CV_32FC4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, target.framebuffer.id());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, image.cols, image.rows, GL_RGBA, GL_FLOAT, image.data);
    return image;
}

const cv::Mat& Pipeline::filledDepth() const
{
    return impl_->prepared.metres;
}

double Pipeline::invalidDepthFraction() const
{
    return impl_->prepared.invalidFraction;
}

const FrameTimings& Pipeline::timings() const
{
    return impl_->timings;
}

} // namespace defocus
