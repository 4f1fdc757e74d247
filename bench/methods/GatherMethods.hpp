// SPDX-License-Identifier: LGPL-2.1-or-later
// The older single-gather methods as registry entries: upload -> CoC pass -> one gather pass ->
// read back. Each owns its targets (reallocated only when size or format changes).
#pragma once

#include "bench/methods/Method.hpp"
#include "bench/passes/GaussianBlurPass.hpp"
#include "bench/passes/LazyGatherPass.hpp"
#include "bench/passes/PoissonGatherPass.hpp"
#include "filter/Lens.hpp"
#include "filter/gl/GpuTimer.hpp"
#include "filter/gl/Objects.hpp"
#include "filter/passes/CocPass.hpp"

namespace defocus {

/// The chain shared by the gather methods; subclasses draw their one pass.
class GatherMethod : public Method {
protected:
    explicit GatherMethod(bool timers);
    MethodResult process(const Frame& frame, const LensSettings& lens, const MethodSettings& settings) final;
    /// Draws the method's pass from `coc` (rgb + signed CoC in pixels) into `target`.
    virtual void gather(const gl::Texture& coc, const gl::Texture& depth, const CocCoefficients& k,
                        const gl::Framebuffer& target) = 0;
    /// The pass's name for GPU timers.
    virtual const char* passName() const = 0;

private:
    /// A texture and the framebuffer that renders into it.
    struct Target {
        gl::Texture texture;
        gl::Framebuffer framebuffer;
        void ensure(GLenum format, cv::Size size, const char* name);
    };
    gl::VertexArray vao_ = gl::VertexArray::create();
    CocPass cocPass_;
    CocParams cocParams_;
    gl::GpuTimer timer_;
    gl::Texture color_, depth_;
    Target coc_, out_;
};

/// "riguer": Riguer et al.'s 12-tap Poisson disc with their bleeding rule.
class RiguerMethod final : public GatherMethod {
public:
    explicit RiguerMethod(bool timers) : GatherMethod(timers) {}
    const MethodInfo& info() const override;

private:
    void gather(const gl::Texture& coc, const gl::Texture& depth, const CocCoefficients& k,
                const gl::Framebuffer& target) override;
    const char* passName() const override { return PoissonGatherPass::kName; }
    PoissonGatherPass pass_;
};

/// "lazy8": the 8-point lazy gather with the blurriness-difference threshold.
class LazyMethod final : public GatherMethod {
public:
    explicit LazyMethod(bool timers) : GatherMethod(timers) {}
    const MethodInfo& info() const override;

private:
    void gather(const gl::Texture& coc, const gl::Texture& depth, const CocCoefficients& k,
                const gl::Framebuffer& target) override;
    const char* passName() const override { return LazyGatherPass::kName; }
    LazyGatherPass pass_;
};

/// "gaussian5x5": the 5x5 Gaussian spread by |CoC|.
class GaussianMethod final : public GatherMethod {
public:
    explicit GaussianMethod(bool timers) : GatherMethod(timers) {}
    const MethodInfo& info() const override;

private:
    void gather(const gl::Texture& coc, const gl::Texture& depth, const CocCoefficients& k,
                const gl::Framebuffer& target) override;
    const char* passName() const override { return GaussianBlurPass::kName; }
    GaussianBlurPass pass_;
};

} // namespace defocus
