// SPDX-License-Identifier: LGPL-2.1-or-later
// libdefocus: the public Source (include/defocus/Source.hpp) over the command line's sources, and
// over the synthetic scenes, rendered in a GL context of the Source's own.
#include "defocus/Source.hpp"

#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "filter/ApiSettings.hpp"
#include "filter/gl/EglContext.hpp"
#include "filter/gl/Program.hpp"
#include "sources/FrameSource.hpp"
#include "sources/ReadAheadSource.hpp"
#include "sources/SyntheticSource.hpp"

namespace defocus {

struct Source::Impl {
    std::optional<gl::EglContext> context; ///< a synthetic scene's; none for other inputs
    std::unique_ptr<FrameSource> source;
    SyntheticSource* synthetic = nullptr; ///< source, when it is a synthetic scene

    /// The synthetic scene's context current on this thread for one call (nothing otherwise).
    std::optional<gl::EglContext::Scope> bind() const
    {
        if (!context)
            return std::nullopt;
        try {
            return std::optional<gl::EglContext::Scope>(std::in_place, *context);
        } catch (const gl::ContextError& error) {
            throw GlError(fmt::format("defocus::Source: {} (a Source is used by one thread at a time)", error.what()));
        }
    }

    /// Renders settings.synthetic, in a context of its own.
    void openSynthetic(const SourceSettings& settings)
    {
        const SyntheticClip& clip = *settings.synthetic;
        SyntheticSettings scene;
        scene.frames = clip.frames;
        scene.lens = toLens(clip.lens);
        scene.focusPull = clip.focusPull;
        if (const auto issues = validate(scene); !issues.empty())
            throw SettingsError(fmt::format("synthetic scene: {}", issues.front()));
        try {
            const gl::EglContext::Binding before = gl::EglContext::Binding::current();
            gl::ContextOptions options;
            options.device = settings.context.eglDevice;
            context.emplace(gl::EglContext::create(options));
            const gl::EglContext::Scope bound(*context, before);
            auto made = std::make_unique<SyntheticSource>(syntheticScene(clip.scene), scene);
            synthetic = made.get();
            source = std::move(made);
        } catch (const gl::ContextError& error) {
            throw GlError(error.what());
        } catch (const gl::ShaderError& error) {
            throw GlError(error.what());
        } catch (const std::invalid_argument& error) { // a scene name syntheticScene() does not know
            throw SettingsError(error.what());
        }
    }

    ~Impl()
    {
        if (!context)
            return;
        try {
            const auto bound = bind(); // the scene's GL objects are deleted with their context
            source.reset();
        } catch (const Error&) {
            // Another thread is inside a call (a caller's bug): the objects go with the context.
        }
    }
};

std::vector<std::string> syntheticScenes()
{
    return syntheticSceneNames();
}

Source::Source(const SourceSettings& settings) : impl_(std::make_unique<Impl>())
{
    if (settings.synthetic) {
        impl_->openSynthetic(settings);
        return;
    }
    SourceOptions options;
    options.input = settings.input;
    if (!settings.depth.empty())
        options.depth = settings.depth;
    options.depthScale = settings.depthScale;
    options.depthUnits = settings.depthUnits;
    options.yuvColor = settings.yuvColor;
    options.width = settings.width;
    options.height = settings.height;
    options.fps = settings.fps;
    try {
        impl_->source = openSource(options);
    } catch (const SourceError& error) {
        throw SourceReadError(error.what());
    }
    if (settings.readThreads > 0 && !impl_->source->isLive())
        impl_->source = ReadAheadSource::onThreads(std::move(impl_->source), settings.readThreads);
}

std::size_t defaultReadThreads(std::size_t clips)
{
    return ReadAheadSource::defaultThreads(clips);
}

Source::~Source() = default;
Source::Source(Source&&) noexcept = default;
Source& Source::operator=(Source&&) noexcept = default;

std::optional<SourceFrame> Source::next()
{
    const auto bound = impl_->bind();
    try {
        return impl_->source->next();
    } catch (const SourceError& error) {
        throw SourceReadError(error.what());
    }
}

std::optional<std::size_t> Source::frameCount() const
{
    return impl_->source->frameCount();
}

double Source::frameRate() const
{
    return impl_->source->frameRate();
}

bool Source::isLive() const
{
    return impl_->source->isLive();
}

std::string Source::describe() const
{
    return impl_->source->describe();
}

std::optional<double> Source::sceneFocusM(std::size_t index) const
{
    if (!impl_->synthetic || !impl_->synthetic->scene().settings().focusPull)
        return std::nullopt;
    return impl_->synthetic->lensAt(index).focusM;
}

} // namespace defocus
