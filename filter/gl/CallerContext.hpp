// SPDX-License-Identifier: LGPL-2.1-or-later
// A context the filter shares with its owner (a GstGLContext, an application's): what it is, its
// textures read back, and its GL state saved when the filter starts a call, set to what the
// passes assume, and put back at the call's end.
#pragma once

#include <array>
#include <string>

#include <epoxy/gl.h>
#include <opencv2/core.hpp>

#include "filter/gl/EglContext.hpp"

namespace defocus::gl {

/// The context current on the calling thread (EGL or GLX); platform "caller", no EGL strings
/// where it is not EGL. Throws ContextError where none is current or it is not OpenGL 4.5.
ContextInfo callerContextInfo();

/// The size of `texture`, a 2D texture of the current context of internal format
/// `internalFormat`; throws ContextError naming `what` (e.g. "colour texture") otherwise.
cv::Size textureSize(GLuint texture, GLenum internalFormat, const char* what);
/// Level 0 of `texture` (size `size`) read back as `format`/`type` into an image of `cvType`.
cv::Mat readTexture(GLuint texture, cv::Size size, GLenum format, GLenum type, int cvType);

/// Depth texture formats, in the order of defocus::GlFrame::DepthFormat.
enum class DepthTexture { R16, Rg8Le, R32F };
/// A depth texture read back: CV_16UC1 units (GL_R16; GL_RG8 holding little-endian 16-bit, red
/// the low byte) or CV_32FC1 metres (GL_R32F). Throws ContextError as textureSize() does.
cv::Mat readDepthTexture(GLuint texture, DepthTexture format);

/// For the life of the object, the current context's state is the passes' (FRAMEBUFFER_SRGB on;
/// blending, depth, stencil, scissor and culling off; additive blending when a pass enables it;
/// all colour channels written; tight pixel rows; no pixel buffers bound); then the caller's again:
/// the framebuffers, viewport, program, vertex array, active texture, the 2D texture and sampler
/// bindings of units [0, kUnits), the image units the compute passes store through [0,
/// kImageUnits), pixel-store alignment and row length, pixel buffers, draw-indirect and the
/// generic uniform and storage buffers, blend function and equation, colour mask and those
/// enables. Indexed uniform and storage buffer bindings are not put back.
class CallerState {
public:
    static constexpr int kUnits = 8;
    static constexpr int kImageUnits = 2;
    CallerState();
    ~CallerState();
    CallerState(const CallerState&) = delete;
    CallerState& operator=(const CallerState&) = delete;

private:
    static constexpr std::array<GLenum, 6> kEnables = {GL_FRAMEBUFFER_SRGB, GL_BLEND,        GL_DEPTH_TEST,
                                                       GL_STENCIL_TEST,     GL_SCISSOR_TEST, GL_CULL_FACE};
    std::array<GLboolean, kEnables.size()> enabled_{};
    GLint drawFramebuffer_ = 0, readFramebuffer_ = 0, program_ = 0, vertexArray_ = 0, activeTexture_ = 0;
    GLint viewport_[4] = {0, 0, 0, 0};
    std::array<GLint, kUnits> textures_{}, samplers_{};
    struct ImageUnit {
        GLint texture = 0, level = 0, layered = GL_FALSE, layer = 0, access = GL_READ_ONLY, format = GL_R8;
    };
    std::array<ImageUnit, kImageUnits> images_{};
    GLint packAlignment_ = 4, unpackAlignment_ = 4, packRowLength_ = 0, unpackRowLength_ = 0;
    GLint packBuffer_ = 0, unpackBuffer_ = 0, indirectBuffer_ = 0, uniformBuffer_ = 0, storageBuffer_ = 0;
    GLint blendSrcRgb_ = GL_ONE, blendDstRgb_ = GL_ZERO, blendSrcAlpha_ = GL_ONE, blendDstAlpha_ = GL_ZERO;
    GLint blendEquationRgb_ = GL_FUNC_ADD, blendEquationAlpha_ = GL_FUNC_ADD;
    GLboolean colorMask_[4] = {GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE};
};

} // namespace defocus::gl
