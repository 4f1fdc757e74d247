// SPDX-License-Identifier: LGPL-2.1-or-later
// The gather methods' shared chain (upload, CoC pass, one pass, readback, GPU timers) and their
// one-pass bodies.
#include "bench/methods/GatherMethods.hpp"

#include <cmath>

#include <epoxy/gl.h>

#include "filter/DepthPrep.hpp"

namespace defocus {

void GatherMethod::Target::ensure(GLenum format, cv::Size size, const char* name)
{
    if (texture && texture.format() == format && texture.width() == size.width && texture.height() == size.height)
        return;
    framebuffer = {};
    texture = gl::Texture(format, size.width, size.height, name);
    framebuffer = gl::Framebuffer(texture, name);
}

namespace {

bool timerQueriesAvailable()
{
    GLint bits = 0;
    glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
    return bits > 0;
}

void ensureTexture(gl::Texture& texture, GLenum format, cv::Size size, const char* name)
{
    if (!texture || texture.format() != format || texture.width() != size.width || texture.height() != size.height)
        texture = gl::Texture(format, size.width, size.height, name);
}

} // namespace

GatherMethod::GatherMethod(bool timers) : timer_(timers && timerQueriesAvailable()) {}

MethodResult GatherMethod::process(const Frame& frame, const LensSettings& lens, const MethodSettings& settings)
{
    CV_Assert(!frame.color.empty() && (frame.color.type() == CV_8UC3 || frame.color.type() == CV_32FC3));
    const cv::Size size = frame.color.size();
    const float fallback = std::isinf(lens.focusM) ? 1e6f : static_cast<float>(lens.focusM);
    const PreparedDepth prepared = prepareDepth(frame.depth, size, fallback);
    const CocCoefficients k = cocCoefficients(lens, size.width);

    const bool srgbInput = frame.color.type() == CV_8UC3;
    ensureTexture(color_, srgbInput ? GL_SRGB8 : GL_RGB32F, size, "input colour");
    ensureTexture(depth_, GL_R32F, size, "filled depth");
    CV_Assert(frame.color.isContinuous() && prepared.metres.isContinuous());
    color_.upload(GL_BGR, srgbInput ? GL_UNSIGNED_BYTE : GL_FLOAT, frame.color.data);
    depth_.upload(GL_RED, GL_FLOAT, prepared.metres.data);

    const bool half = settings.precision == TargetFormat::Rgba16F;
    const GLenum format = half ? GL_RGBA16F : GL_RGBA32F;
    coc_.ensure(format, size, "coc");
    out_.ensure(format, size, passName());

    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(vao_.id());
    timer_.begin(CocPass::kName);
    cocParams_.set(k, half);
    cocPass_.run(color_, depth_, cocParams_, coc_.framebuffer);
    timer_.end();
    timer_.begin(passName());
    gather(coc_.texture, depth_, k, out_.framebuffer);
    timer_.end();

    MethodResult result;
    result.linear.create(size, CV_32FC3);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, out_.framebuffer.id());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, size.width, size.height, GL_BGR, GL_FLOAT, result.linear.data);
    timer_.swap(); // ends this frame's scopes; drain() then reads them (the GPU is done: readback waited)
    for (auto& [name, ms] : timer_.drain())
        result.gpu.push_back({name, ms});
    return result;
}

void RiguerMethod::gather(const gl::Texture& coc, const gl::Texture& depth, const CocCoefficients& k,
                          const gl::Framebuffer& target)
{
    pass_.run(coc, depth, k.maxCocPx, target);
}

void LazyMethod::gather(const gl::Texture& coc, const gl::Texture&, const CocCoefficients& k,
                        const gl::Framebuffer& target)
{
    pass_.run(coc, k.maxCocPx, LazyGatherPass::kDefaultThreshold, target);
}

void GaussianMethod::gather(const gl::Texture& coc, const gl::Texture&, const CocCoefficients&,
                            const gl::Framebuffer& target)
{
    pass_.run(coc, target);
}

} // namespace defocus
