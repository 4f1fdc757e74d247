// SPDX-License-Identifier: LGPL-2.1-or-later
// Depth prep on the GPU: nearest-neighbour resize, push-pull hole filling, the lights' edges.
#include "filter/passes/DepthPrepPass.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "filter/passes/Pass.hpp"

namespace defocus {

namespace {

gl::Program program(const char* step, const char* name, const char* variant = nullptr)
{
    std::vector<std::string> defines{std::string(step) + " 1"};
    if (variant)
        defines.push_back(std::string(variant) + " 1");
    return gl::Program("fullscreen.vert", "depth_prep.frag", name, defines);
}

} // namespace

DepthPrepPass::DepthPrepPass()
    : split_(program("SPLIT", "depth prep: split")),
      splitUnits_(program("SPLIT", "depth prep: split, 16-bit units", "UNITS")),
      push_(program("PUSH", "depth prep: push")), pull_(program("PULL", "depth prep: pull")), fill_(program("FILL", "depth prep: fill")),
      lightEdges_(program("LIGHT_EDGES", "depth prep: light edges")), nearest_(GL_NEAREST, "depth prep nearest")
{
}

void DepthPrepPass::draw(const gl::Program& program, const gl::Framebuffer& target) const
{
    glProgramUniform2i(staged(program).id(), kSizeLocation, target.width(), target.height());
    shade(program, target);
}

void DepthPrepPass::run(const gl::Texture* depth, double unitsPerMetre, float fallbackM,
                        const gl::Texture* lightColor, const gl::Texture& filledDepth,
                        const gl::Framebuffer& filled)
{
    const int width = filled.width(), height = filled.height();
    if (lightColor && (!unlit_ || unlit_.width() != width || unlit_.height() != height)) {
        unlit_ = gl::Texture(GL_R32F, width, height, "filled depth, lights' edges unmoved");
        unlitTarget_ = gl::Framebuffer(unlit_, "filled depth, lights' edges unmoved");
    }
    const gl::Framebuffer& target = lightColor ? unlitTarget_ : filled;
    for (GLuint unit = 0; unit < 3; ++unit)
        glBindSampler(unit, nearest_.id());
    if (!depth) {
        glClearTexImage((lightColor ? unlit_ : filledDepth).id(), 0, GL_RED, GL_FLOAT, &fallbackM);
    } else {
        // The pyramid: the frame's size, then halves rounded up down to 1x1, at least one level
        // below the frame (FILL reads it). Level 0 and the coarsest have no filled texture:
        // FILL writes the frame's, and the coarsest is its own.
        std::size_t count = 0;
        for (int w = width, h = height; count < 2 || w > 1 || h > 1; ++count) {
            if (count > 0) {
                w = (w + 1) / 2;
                h = (h + 1) / 2;
            }
            if (levels_.size() <= count)
                levels_.resize(count + 1);
            Level& level = levels_[count];
            if (!level.pyramid || level.pyramid.width() != w || level.pyramid.height() != h) {
                level.pyramid = gl::Texture(GL_RG32F, w, h, "depth pyramid");
                level.pyramidTarget = gl::Framebuffer(level.pyramid, "depth pyramid");
                level.filled = {};
                level.filledTarget = {};
            }
        }
        for (std::size_t i = 1; i + 1 < count; ++i)
            if (!levels_[i].filled) {
                const int w = levels_[i].pyramid.width(), h = levels_[i].pyramid.height();
                levels_[i].filled = gl::Texture(GL_R32F, w, h, "depth pyramid, filled");
                levels_[i].filledTarget = gl::Framebuffer(levels_[i].filled, "depth pyramid, filled");
            }
        glBindTextureUnit(0, depth->id());
        if (unitsPerMetre > 0.0) {
            glProgramUniform1f(staged(splitUnits_).id(), kMetresPerUnitLocation, static_cast<float>(1.0 / unitsPerMetre));
            draw(splitUnits_, levels_[0].pyramidTarget);
        } else {
            draw(split_, levels_[0].pyramidTarget);
        }
        for (std::size_t i = 1; i < count; ++i) {
            glBindTextureUnit(0, levels_[i - 1].pyramid.id());
            draw(push_, levels_[i].pyramidTarget);
        }
        // The coarsest level is its own filled depth (its r); each finer one pulls from the next.
        const auto filledOf = [&](std::size_t i) {
            return i + 1 == count ? levels_[i].pyramid.id() : levels_[i].filled.id();
        };
        for (std::size_t i = count - 2; i >= 1; --i) {
            glBindTextureUnit(0, levels_[i].pyramid.id());
            glBindTextureUnit(1, filledOf(i + 1));
            draw(pull_, levels_[i].filledTarget);
        }
        glBindTextureUnit(0, levels_[0].pyramid.id());
        glBindTextureUnit(1, filledOf(1));
        glBindTextureUnit(2, levels_[count - 1].pyramid.id());
        glProgramUniform1f(staged(fill_).id(), kFallbackLocation, fallbackM);
        draw(fill_, target);
    }
    if (lightColor) {
        glBindTextureUnit(0, lightColor->id());
        glBindTextureUnit(1, unlit_.id());
        draw(lightEdges_, filled);
    }
}

} // namespace defocus
