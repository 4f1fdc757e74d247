// SPDX-License-Identifier: LGPL-2.1-or-later
// What every pass shares: a human-readable name (GL labels, logs, GPU timers), the full-screen
// triangle draw, and shade(): a pass's fragment shader over its target, drawn or run as a compute
// shader. Passes take explicit inputs and write the target they are given.
#pragma once

#include <cassert>

#include <epoxy/gl.h>

#include "filter/gl/Program.hpp"
#include "filter/passes/TileList.hpp"

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

/// How a pass runs its fragment shaders: drawn (the rasteriser shades the target's pixels), or
/// as compute shaders over the same pixels (gl::Program::computeForm()), which a datacenter GPU
/// runs on every one of its processing clusters instead of the few that draw.
enum class ShaderStage : bool { Fragment, Compute };

/// Runs `program` (with fullscreen.vert, or tiles.vert when `tiles` is given) over every pixel of
/// `target`, or of `tiles`: drawn, or dispatched as its compute form, after which image stores
/// are made visible to whatever reads the target next (textures, draws, reads, copies).
inline void shade(const gl::Program& program, const gl::Framebuffer& target, const TileList* tiles, ShaderStage stage)
{
    if (stage == ShaderStage::Fragment) {
        target.bindForDraw();
        program.use();
        if (tiles)
            tiles->draw();
        else
            drawFullscreenTriangle();
        return;
    }
    const gl::Program& compute = program.computeForm();
    compute.use();
    assert(target.storeCount() > 0);
    glProgramUniform1ui(compute.id(), compute.computeSrgbLocation(), target.bindForStore());
    if (tiles)
        tiles->dispatch();
    else
        glDispatchCompute(static_cast<GLuint>((target.width() + 7) / 8), static_cast<GLuint>((target.height() + 7) / 8), 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT |
                    GL_PIXEL_BUFFER_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

/// A pass that shades its targets with shade(): it keeps whether it draws or dispatches, which
/// the pipeline sets for all its passes at once (Pipeline::computePasses()).
class ShadedPass {
public:
    /// Draws its fragment shaders or runs them as compute shaders.
    void setStage(ShaderStage stage) { stage_ = stage; }
    ShaderStage stage() const { return stage_; }

protected:
    /// defocus::shade() in this pass's stage.
    void shade(const gl::Program& program, const gl::Framebuffer& target, const TileList* tiles = nullptr) const
    {
        defocus::shade(program, target, tiles, stage_);
    }

private:
    ShaderStage stage_ = ShaderStage::Fragment;
};

} // namespace defocus
