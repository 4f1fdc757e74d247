// SPDX-License-Identifier: LGPL-2.1-or-later
// A headless OpenGL 4.5 core context through EGL, with no window system: the EGL device platform
// first (what a headless NVIDIA GPU offers), then Mesa's surfaceless platform (llvmpipe on CI).
// Which device: one asked for by index (defocus --egl-device N), else the GPU that CUDA sees first
// when CUDA_VISIBLE_DEVICES is set (as Slurm sets it for --gres=gpu), matched through the EGL
// device's CUDA id where the driver offers EGL_NV_device_cuda, else the devices in order.
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

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
    int device = -1;           ///< index of the EGL device in use; -1 on the surfaceless platform
};

/// One EGL device, as eglQueryDevicesEXT lists it.
struct DeviceInfo {
    int index = 0;
    std::string drmFile;        ///< EGL_DRM_DEVICE_FILE_EXT, e.g. "/dev/dri/card1"; empty when not offered
    std::optional<int> cudaId;  ///< EGL_CUDA_DEVICE_NV: the CUDA device it is, as this process's CUDA numbers them
    bool software = false;      ///< EGL_MESA_device_software (llvmpipe)
};

struct ContextOptions {
    bool debug = false; ///< route GL debug messages to the log
    /// Only this EGL device (an index into devices()); unset: the CUDA device when
    /// CUDA_VISIBLE_DEVICES names one, else the first device that works, then surfaceless.
    std::optional<int> device;
};

/// The order create() tries `devices` in (indices into it): only `requested` when set; else,
/// when `cudaVisible` names a GPU, the device whose CUDA id is 0 (CUDA numbers the visible GPUs
/// from 0 in their CUDA_VISIBLE_DEVICES order, and EGL_CUDA_DEVICE_NV gives that number) first,
/// then the others in order. Pure, for tests.
std::vector<int> deviceOrder(const std::vector<DeviceInfo>& devices, std::optional<int> requested,
                             const std::optional<std::string>& cudaVisible);

/// Owns an EGL display + context and makes it current on the creating thread. Move-only.
class EglContext {
public:
    /// Creates the context; throws ContextError naming each platform tried and why it failed.
    /// Set `debug` to route GL debug messages to the log.
    static EglContext create(bool debug = false);
    /// The same with a device choice; an unusable `options.device` throws ContextError naming
    /// it and the devices there are (no fallback to another device).
    static EglContext create(const ContextOptions& options);
    /// The EGL devices of this machine (empty without EGL_EXT_device_enumeration).
    static std::vector<DeviceInfo> devices();
    /// The EGLDisplay create(options) renders on, initialised and never terminated (another
    /// library may hold it for the rest of the process). Throws ContextError as create() does.
    static void* keepDisplay(const ContextOptions& options);

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

    /// What is current on the calling thread: EGLDisplay, EGLSurfaces and EGLContext, as opaque
    /// handles (all null: nothing).
    struct Binding {
        void* display = nullptr;
        void* draw = nullptr;
        void* read = nullptr;
        void* context = nullptr;
        static Binding current();
    };

    /// This context current on the calling thread for the life of the Scope; then what was
    /// current on the thread before (another context, or none) is current again, so that the
    /// context is free for any thread between calls and a caller's own context is left as it
    /// was. A Scope of a context already current on this thread changes nothing. Throws
    /// ContextError when the context cannot be made current (it is current on another thread).
    class Scope {
    public:
        /// Changes nothing (a Filter on its caller's context has no context of its own).
        Scope() = default;
        explicit Scope(const EglContext& context);
        /// For a context already made current on this thread (create() does): `before` is what
        /// was current before, put back at the end.
        Scope(const EglContext& context, const Binding& before);
        ~Scope();
        Scope(const Scope&) = delete;
        Scope& operator=(const Scope&) = delete;

    private:
        const EglContext* context_ = nullptr; ///< null: the context was current already
        Binding previous_;
    };

private:
    explicit EglContext(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
    ContextInfo info_;
};

} // namespace defocus::gl
