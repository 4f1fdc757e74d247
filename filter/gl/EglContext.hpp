// A headless OpenGL 4.5 core context through EGL, with no window system: the EGL device platform
// first (what a headless NVIDIA GPU offers), then Mesa's surfaceless platform (llvmpipe on CI).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

namespace defocus::gl {

/// Thrown when no usable EGL/GL context can be made; the message says everything that was tried.
class ContextError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct ContextInfo {
    std::string platform;    ///< "device" or "surfaceless"
    std::string eglVendor;   ///< EGL_VENDOR
    std::string eglVersion;  ///< EGL_VERSION
    std::string glVendor;    ///< GL_VENDOR
    std::string glRenderer;  ///< GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    std::string glVersion;   ///< GL_VERSION
    bool timerQueries = false; ///< GL_TIME_ELAPSED queries give results
};

/// Owns an EGL display + context and makes it current on the creating thread. Move-only.
class EglContext {
public:
    /// Creates the context; throws ContextError naming each platform tried and why it failed.
    /// Set `debug` to route GL debug messages to the log.
    static EglContext create(bool debug = false);

    EglContext(EglContext&&) noexcept;
    EglContext& operator=(EglContext&&) noexcept;
    EglContext(const EglContext&) = delete;
    EglContext& operator=(const EglContext&) = delete;
    ~EglContext();

    const ContextInfo& info() const { return info_; }
    /// Makes the context current on the calling thread.
    void makeCurrent() const;
    /// True when this context is current on the calling thread.
    bool isCurrent() const;
    /// Unbinds whatever context is current on the calling thread, so that another thread can
    /// make this one current.
    void release() const;

    struct State; ///< display + context, defined in the .cpp

private:
    explicit EglContext(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
    ContextInfo info_;
};

} // namespace defocus::gl
