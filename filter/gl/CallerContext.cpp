// SPDX-License-Identifier: LGPL-2.1-or-later
// The caller's context: its description, its textures checked and read back, and CallerState
// (glGet of what the passes change, the passes' assumptions set, everything put back).
#include "filter/gl/CallerContext.hpp"

#include <epoxy/egl.h>
#include <fmt/format.h>

namespace defocus::gl {

namespace {

std::string glString(GLenum name)
{
    const auto* text = reinterpret_cast<const char*>(glGetString(name));
    return text ? text : "";
}

} // namespace

ContextInfo callerContextInfo()
{
    ContextInfo info;
    info.platform = "caller";
    const EGLDisplay display = eglGetCurrentDisplay();
    if (eglGetCurrentContext() != EGL_NO_CONTEXT && display != EGL_NO_DISPLAY) {
        info.eglVendor = eglQueryString(display, EGL_VENDOR);
        info.eglVersion = eglQueryString(display, EGL_VERSION);
    }
    info.glVersion = glString(GL_VERSION);
    if (info.glVersion.empty())
        throw ContextError("defocus::gl::callerContextInfo(): no OpenGL context is current on this thread "
                           "(ContextOptions::callerContext renders on the caller's)");
    info.glVendor = glString(GL_VENDOR);
    info.glRenderer = glString(GL_RENDERER);
    if (epoxy_gl_version() < 45)
        throw ContextError(fmt::format("defocus::gl::callerContextInfo(): the current context ({}) offers OpenGL "
                                       "{}, 4.5 is needed",
                                       info.glRenderer, info.glVersion));
    GLint timerBits = 0;
    glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &timerBits);
    info.timerQueries = timerBits > 0;
    return info;
}

cv::Size textureSize(GLuint texture, GLenum internalFormat, const char* what)
{
    GLint target = 0, format = 0, width = 0, height = 0;
    if (texture != 0 && glIsTexture(texture)) {
        glGetTextureParameteriv(texture, GL_TEXTURE_TARGET, &target);
        glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
        glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_WIDTH, &width);
        glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_HEIGHT, &height);
    }
    if (target != GL_TEXTURE_2D || width <= 0 || height <= 0)
        throw ContextError(fmt::format("{} {} is not a 2D texture of the current context", what, texture));
    if (static_cast<GLenum>(format) != internalFormat)
        throw ContextError(fmt::format("{} {} has internal format 0x{:04x}, not 0x{:04x}", what, texture, format,
                                       internalFormat));
    return {width, height};
}

cv::Mat readTexture(GLuint texture, cv::Size size, GLenum format, GLenum type, int cvType)
{
    cv::Mat image(size, cvType);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(texture, 0, format, type, static_cast<GLsizei>(image.total() * image.elemSize()), image.data);
    return image;
}

CallerState::CallerState()
{
    for (std::size_t i = 0; i < kEnables.size(); ++i)
        enabled_[i] = glIsEnabled(kEnables[i]);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFramebuffer_);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readFramebuffer_);
    glGetIntegerv(GL_VIEWPORT, viewport_);
    glGetIntegerv(GL_CURRENT_PROGRAM, &program_);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vertexArray_);
    glGetIntegerv(GL_ACTIVE_TEXTURE, &activeTexture_);
    for (int unit = 0; unit < kUnits; ++unit) {
        glActiveTexture(static_cast<GLenum>(GL_TEXTURE0 + unit));
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &textures_[static_cast<std::size_t>(unit)]);
        glGetIntegerv(GL_SAMPLER_BINDING, &samplers_[static_cast<std::size_t>(unit)]);
    }
    glActiveTexture(static_cast<GLenum>(activeTexture_));
    for (int unit = 0; unit < kImageUnits; ++unit) {
        ImageUnit& image = images_[static_cast<std::size_t>(unit)];
        const auto index = static_cast<GLuint>(unit);
        glGetIntegeri_v(GL_IMAGE_BINDING_NAME, index, &image.texture);
        glGetIntegeri_v(GL_IMAGE_BINDING_LEVEL, index, &image.level);
        glGetIntegeri_v(GL_IMAGE_BINDING_LAYERED, index, &image.layered);
        glGetIntegeri_v(GL_IMAGE_BINDING_LAYER, index, &image.layer);
        glGetIntegeri_v(GL_IMAGE_BINDING_ACCESS, index, &image.access);
        glGetIntegeri_v(GL_IMAGE_BINDING_FORMAT, index, &image.format);
    }
    glGetIntegerv(GL_PACK_ALIGNMENT, &packAlignment_);
    glGetIntegerv(GL_UNPACK_ALIGNMENT, &unpackAlignment_);
    glGetIntegerv(GL_PACK_ROW_LENGTH, &packRowLength_);
    glGetIntegerv(GL_UNPACK_ROW_LENGTH, &unpackRowLength_);
    glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &packBuffer_);
    glGetIntegerv(GL_PIXEL_UNPACK_BUFFER_BINDING, &unpackBuffer_);
    glGetIntegerv(GL_DRAW_INDIRECT_BUFFER_BINDING, &indirectBuffer_);
    glGetIntegerv(GL_UNIFORM_BUFFER_BINDING, &uniformBuffer_);
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_BINDING, &storageBuffer_);
    glGetIntegerv(GL_BLEND_SRC_RGB, &blendSrcRgb_);
    glGetIntegerv(GL_BLEND_DST_RGB, &blendDstRgb_);
    glGetIntegerv(GL_BLEND_SRC_ALPHA, &blendSrcAlpha_);
    glGetIntegerv(GL_BLEND_DST_ALPHA, &blendDstAlpha_);
    glGetIntegerv(GL_BLEND_EQUATION_RGB, &blendEquationRgb_);
    glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &blendEquationAlpha_);
    glGetBooleanv(GL_COLOR_WRITEMASK, colorMask_);

    // What the passes assume (a context of the filter's own starts so, and Pipeline sets the rest).
    glEnable(GL_FRAMEBUFFER_SRGB);
    for (std::size_t i = 1; i < kEnables.size(); ++i)
        glDisable(kEnables[i]);
    glBlendEquation(GL_FUNC_ADD);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
}

CallerState::~CallerState()
{
    for (std::size_t i = 0; i < kEnables.size(); ++i)
        (enabled_[i] ? glEnable : glDisable)(kEnables[i]);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(drawFramebuffer_));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(readFramebuffer_));
    glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
    glUseProgram(static_cast<GLuint>(program_));
    glBindVertexArray(static_cast<GLuint>(vertexArray_));
    for (int unit = 0; unit < kUnits; ++unit) {
        glActiveTexture(static_cast<GLenum>(GL_TEXTURE0 + unit));
        glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(textures_[static_cast<std::size_t>(unit)]));
        glBindSampler(static_cast<GLuint>(unit), static_cast<GLuint>(samplers_[static_cast<std::size_t>(unit)]));
    }
    glActiveTexture(static_cast<GLenum>(activeTexture_));
    for (int unit = 0; unit < kImageUnits; ++unit) {
        const ImageUnit& image = images_[static_cast<std::size_t>(unit)];
        glBindImageTexture(static_cast<GLuint>(unit), static_cast<GLuint>(image.texture), image.level,
                           static_cast<GLboolean>(image.layered), image.layer, static_cast<GLenum>(image.access),
                           static_cast<GLenum>(image.format));
    }
    glPixelStorei(GL_PACK_ALIGNMENT, packAlignment_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, unpackAlignment_);
    glPixelStorei(GL_PACK_ROW_LENGTH, packRowLength_);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, unpackRowLength_);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, static_cast<GLuint>(packBuffer_));
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, static_cast<GLuint>(unpackBuffer_));
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, static_cast<GLuint>(indirectBuffer_));
    glBindBuffer(GL_UNIFORM_BUFFER, static_cast<GLuint>(uniformBuffer_));
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(storageBuffer_));
    glBlendFuncSeparate(static_cast<GLenum>(blendSrcRgb_), static_cast<GLenum>(blendDstRgb_),
                        static_cast<GLenum>(blendSrcAlpha_), static_cast<GLenum>(blendDstAlpha_));
    glBlendEquationSeparate(static_cast<GLenum>(blendEquationRgb_), static_cast<GLenum>(blendEquationAlpha_));
    glColorMask(colorMask_[0], colorMask_[1], colorMask_[2], colorMask_[3]);
}

cv::Mat readDepthTexture(GLuint texture, DepthTexture format)
{
    switch (format) {
    case DepthTexture::R16:
        return readTexture(texture, textureSize(texture, GL_R16, "depth texture"), GL_RED, GL_UNSIGNED_SHORT, CV_16UC1);
    case DepthTexture::R32F:
        return readTexture(texture, textureSize(texture, GL_R32F, "depth texture"), GL_RED, GL_FLOAT, CV_32FC1);
    case DepthTexture::Rg8Le: break;
    }
    const cv::Mat bytes =
        readTexture(texture, textureSize(texture, GL_RG8, "depth texture"), GL_RG, GL_UNSIGNED_BYTE, CV_8UC2);
    cv::Mat units(bytes.size(), CV_16UC1);
    for (int y = 0; y < bytes.rows; ++y) {
        const auto* in = bytes.ptr<std::uint8_t>(y);
        auto* out = units.ptr<std::uint16_t>(y);
        for (int x = 0; x < bytes.cols; ++x)
            out[x] = static_cast<std::uint16_t>(in[2 * x] | (in[2 * x + 1] << 8));
    }
    return units;
}

} // namespace defocus::gl
