// SPDX-License-Identifier: LGPL-2.1-or-later
// libdefocus: the public Source (include/defocus/Source.hpp) over the command line's sources.
#include "defocus/Source.hpp"

#include <utility>

#include "sources/FrameSource.hpp"

namespace defocus {

struct Source::Impl {
    std::unique_ptr<FrameSource> source;
};

Source::Source(const SourceSettings& settings) : impl_(std::make_unique<Impl>())
{
    SourceOptions options;
    options.input = settings.input;
    if (!settings.depth.empty())
        options.depth = settings.depth;
    options.depthScale = settings.depthScale;
    options.width = settings.width;
    options.height = settings.height;
    options.fps = settings.fps;
    try {
        impl_->source = openSource(options);
    } catch (const SourceError& error) {
        throw SourceReadError(error.what());
    }
}

Source::~Source() = default;
Source::Source(Source&&) noexcept = default;
Source& Source::operator=(Source&&) noexcept = default;

std::optional<SourceFrame> Source::next()
{
    std::optional<Frame> frame;
    try {
        frame = impl_->source->next();
    } catch (const SourceError& error) {
        throw SourceReadError(error.what());
    }
    if (!frame)
        return std::nullopt;
    return frame;
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

} // namespace defocus
