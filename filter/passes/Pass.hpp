// SPDX-License-Identifier: LGPL-2.1-or-later
// What every pass shares: a human-readable name (GL labels, logs, GPU timers) and the
// full-screen triangle draw. Passes take explicit inputs and write the target they are given.
#pragma once

#include <epoxy/gl.h>

namespace defocus {

/// Draws shaders/fullscreen.vert's triangle into the bound framebuffer (a VAO must be bound).
inline void drawFullscreenTriangle()
{
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

/// Binds `texture` with `sampler` to texture unit `unit`.
inline void bindTexture(GLuint unit, GLuint texture, GLuint sampler)
{
    glBindTextureUnit(unit, texture);
    glBindSampler(unit, sampler);
}

} // namespace defocus
