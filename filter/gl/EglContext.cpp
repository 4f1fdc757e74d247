// SPDX-License-Identifier: LGPL-2.1-or-later
// EGL device platform first (the device asked for, or CUDA's, or each in turn), Mesa surfaceless
// next; OpenGL 4.5 core; no surface at all.
#include "filter/gl/EglContext.hpp"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "filter/Log.hpp"

namespace defocus::gl {

namespace {

// An EGL display is one per device in a process, and eglTerminate() ends every context on it:
// contexts count their display's users, and the last one terminates it, so that one context's
// end does not pull the display from under another (two filters, or a filter and a renderer).
std::mutex gDisplayUsersLock;
std::map<EGLDisplay, int> gDisplayUsers;

void retainDisplay(EGLDisplay display)
{
    const std::lock_guard guard(gDisplayUsersLock);
    ++gDisplayUsers[display];
}

/// True when the caller was the display's last user.
bool releaseDisplay(EGLDisplay display)
{
    const std::lock_guard guard(gDisplayUsersLock);
    const auto found = gDisplayUsers.find(display);
    if (found == gDisplayUsers.end() || --found->second > 0)
        return false;
    gDisplayUsers.erase(found);
    return true;
}

} // namespace

struct EglContext::State {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;

    ~State()
    {
        if (display == EGL_NO_DISPLAY)
            return;
        // Another context current on this thread stays current.
        if (context != EGL_NO_CONTEXT && eglGetCurrentContext() == context)
            eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (context != EGL_NO_CONTEXT)
            eglDestroyContext(display, context);
        if (releaseDisplay(display))
            eglTerminate(display);
    }
};

namespace {

std::string eglErrorName(EGLint error)
{
    switch (error) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    default: return fmt::format("EGL error 0x{:x}", error);
    }
}

bool hasExtension(const char* list, std::string_view name)
{
    if (list == nullptr)
        return false;
    std::string_view all(list);
    for (std::size_t pos = 0; (pos = all.find(name, pos)) != std::string_view::npos; pos += name.size()) {
        const bool startOk = pos == 0 || all[pos - 1] == ' ';
        const bool endOk = pos + name.size() == all.size() || all[pos + name.size()] == ' ';
        if (startOk && endOk)
            return true;
    }
    return false;
}

void GLAPIENTRY logGlMessage(GLenum, GLenum type, GLuint, GLenum severity, GLsizei, const GLchar* message,
                             const void*)
{
    if (severity == GL_DEBUG_SEVERITY_NOTIFICATION)
        return;
    if (type == GL_DEBUG_TYPE_ERROR)
        logger().error("GL: {}", message);
    else
        logger().debug("GL: {}", message);
}

// Initialises `display`, binds desktop GL and creates a 4.5 core context on it.
// Returns an empty string on success, else why it failed.
std::string tryDisplay(EGLDisplay display, EglContext::State& state, bool debug)
{
    if (display == EGL_NO_DISPLAY)
        return "no display";
    EGLint major = 0, minor = 0;
    if (eglInitialize(display, &major, &minor) != EGL_TRUE)
        return "eglInitialize failed: " + eglErrorName(eglGetError());
    retainDisplay(display);
    state.display = display;
    if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE)
        return "no desktop OpenGL API: " + eglErrorName(eglGetError());

    const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
    EGLConfig config = nullptr;
    if (!hasExtension(extensions, "EGL_KHR_no_config_context")) {
        const EGLint configAttributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint count = 0;
        if (eglChooseConfig(display, configAttributes, &config, 1, &count) != EGL_TRUE || count < 1)
            return "no OpenGL-renderable EGL config";
    }
    const EGLint contextAttributes[] = {
        EGL_CONTEXT_MAJOR_VERSION, 4,
        EGL_CONTEXT_MINOR_VERSION, 5,
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
        EGL_CONTEXT_OPENGL_DEBUG, debug ? EGL_TRUE : EGL_FALSE,
        EGL_NONE};
    state.context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttributes);
    if (state.context == EGL_NO_CONTEXT)
        return "no OpenGL 4.5 core context: " + eglErrorName(eglGetError());
    if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, state.context) != EGL_TRUE)
        return "cannot make the context current without a surface: " + eglErrorName(eglGetError());
    return {};
}

std::string glString(GLenum name)
{
    const auto* text = reinterpret_cast<const char*>(glGetString(name));
    return text ? text : "";
}

} // namespace

namespace {

#ifndef EGL_CUDA_DEVICE_NV
#define EGL_CUDA_DEVICE_NV 0x323A
#endif
#ifndef EGL_DRM_DEVICE_FILE_EXT
#define EGL_DRM_DEVICE_FILE_EXT 0x3233
#endif

bool canEnumerate(const char* clientExtensions)
{
    return hasExtension(clientExtensions, "EGL_EXT_device_enumeration") &&
           hasExtension(clientExtensions, "EGL_EXT_platform_device");
}

std::vector<EGLDeviceEXT> queryDevices()
{
    EGLint count = 0;
    if (eglQueryDevicesEXT(0, nullptr, &count) != EGL_TRUE || count <= 0)
        return {};
    std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
    eglQueryDevicesEXT(count, devices.data(), &count);
    devices.resize(static_cast<std::size_t>(std::max<EGLint>(count, 0)));
    return devices;
}

DeviceInfo describe(EGLDeviceEXT device, int index)
{
    DeviceInfo info;
    info.index = index;
    const char* extensions = eglQueryDeviceStringEXT(device, EGL_EXTENSIONS);
    info.software = hasExtension(extensions, "EGL_MESA_device_software");
    if (hasExtension(extensions, "EGL_EXT_device_drm"))
        if (const char* file = eglQueryDeviceStringEXT(device, EGL_DRM_DEVICE_FILE_EXT))
            info.drmFile = file;
    EGLAttrib cuda = 0;
    if (hasExtension(extensions, "EGL_NV_device_cuda") &&
        eglQueryDeviceAttribEXT(device, EGL_CUDA_DEVICE_NV, &cuda) == EGL_TRUE)
        info.cudaId = static_cast<int>(cuda);
    return info;
}

std::string describeAll(const std::vector<DeviceInfo>& devices)
{
    std::vector<std::string> parts;
    for (const DeviceInfo& d : devices)
        parts.push_back(fmt::format("{}: {}{}", d.index,
                                    d.software ? "software" : d.drmFile.empty() ? "device" : d.drmFile,
                                    d.cudaId ? fmt::format(", CUDA {}", *d.cudaId) : ""));
    return parts.empty() ? "none" : fmt::format("{}", fmt::join(parts, "; "));
}

} // namespace

std::vector<int> deviceOrder(const std::vector<DeviceInfo>& devices, std::optional<int> requested,
                             const std::optional<std::string>& cudaVisible)
{
    const int count = static_cast<int>(devices.size());
    if (requested)
        return *requested >= 0 && *requested < count ? std::vector<int>{*requested} : std::vector<int>{};
    std::vector<int> order;
    if (cudaVisible && !cudaVisible->empty())
        for (int i = 0; i < count; ++i)
            if (devices[static_cast<std::size_t>(i)].cudaId == 0)
                order.push_back(i);
    for (int i = 0; i < count; ++i)
        if (std::find(order.begin(), order.end(), i) == order.end())
            order.push_back(i);
    return order;
}

std::vector<DeviceInfo> EglContext::devices()
{
    std::vector<DeviceInfo> infos;
    if (!canEnumerate(eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS)))
        return infos;
    const auto devices = queryDevices();
    for (std::size_t i = 0; i < devices.size(); ++i)
        infos.push_back(describe(devices[i], static_cast<int>(i)));
    return infos;
}

EglContext EglContext::create(bool debug)
{
    ContextOptions options;
    options.debug = debug;
    return create(options);
}

EglContext EglContext::create(const ContextOptions& options)
{
    const bool debug = options.debug;
    const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    std::vector<std::string> tried;
    auto state = std::make_unique<State>();
    std::string platform;
    int deviceUsed = -1;

    // 1. Device platform: the devices in deviceOrder()'s order, the first that gives a context.
    if (canEnumerate(clientExtensions)) {
        const auto devices = queryDevices();
        std::vector<DeviceInfo> infos;
        for (std::size_t i = 0; i < devices.size(); ++i)
            infos.push_back(describe(devices[i], static_cast<int>(i)));
        const char* cudaVisible = std::getenv("CUDA_VISIBLE_DEVICES");
        const auto order = deviceOrder(infos, options.device,
                                       cudaVisible ? std::optional<std::string>(cudaVisible) : std::nullopt);
        if (options.device && order.empty())
            throw ContextError(fmt::format("defocus::gl::EglContext::create(): there is no EGL device {} "
                                           "(this machine's EGL devices: {})",
                                           *options.device, describeAll(infos)));
        if (devices.empty())
            tried.emplace_back("EGL device platform: no devices");
        for (const int i : order) {
            const auto& device = devices[static_cast<std::size_t>(i)];
            EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
            const std::string why = tryDisplay(display, *state, debug);
            if (why.empty()) {
                platform = infos[static_cast<std::size_t>(i)].software ? "device (software)" : "device";
                deviceUsed = i;
                break;
            }
            tried.push_back(fmt::format("EGL device {}: {}", i, why));
            state = std::make_unique<State>();
        }
        if (options.device && platform.empty())
            throw ContextError(fmt::format("defocus::gl::EglContext::create(): no headless OpenGL 4.5 context ({})",
                                           fmt::join(tried, "; ")));
    } else {
        if (options.device)
            throw ContextError(fmt::format("defocus::gl::EglContext::create(): EGL device {} asked for, but this "
                                           "EGL cannot list devices (no EGL_EXT_device_enumeration)",
                                           *options.device));
        tried.emplace_back("EGL device platform: extension not offered");
    }

    // 2. Mesa's surfaceless platform.
    if (platform.empty()) {
        if (hasExtension(clientExtensions, "EGL_MESA_platform_surfaceless")) {
            EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
            const std::string why = tryDisplay(display, *state, debug);
            if (why.empty())
                platform = "surfaceless";
            else
                tried.push_back("Mesa surfaceless platform: " + why);
        } else {
            tried.emplace_back("Mesa surfaceless platform: extension not offered");
        }
    }

    if (platform.empty())
        throw ContextError(fmt::format("defocus::gl::EglContext::create(): no headless OpenGL 4.5 context ({})",
                                       fmt::join(tried, "; ")));

    EglContext context(std::move(state));
    ContextInfo& info = context.info_;
    info.platform = platform;
    info.device = deviceUsed;
    info.eglVendor = eglQueryString(context.state_->display, EGL_VENDOR);
    info.eglVersion = eglQueryString(context.state_->display, EGL_VERSION);
    info.glVendor = glString(GL_VENDOR);
    info.glRenderer = glString(GL_RENDERER);
    info.glVersion = glString(GL_VERSION);
    GLint timerBits = 0;
    glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &timerBits);
    info.timerQueries = timerBits > 0;
    if (epoxy_gl_version() < 45)
        throw ContextError(fmt::format("defocus::gl::EglContext::create(): {} offers OpenGL {}, 4.5 is needed",
                                       info.glRenderer, info.glVersion));
    if (debug) {
        glEnable(GL_DEBUG_OUTPUT);
        glDebugMessageCallback(logGlMessage, nullptr);
    }
    logger().debug("EGL {} platform{}: {} / {}", info.platform,
                  info.device >= 0 ? fmt::format(" (EGL device {})", info.device) : "", info.glRenderer, info.glVersion);
    return context;
}

EglContext::EglContext(std::unique_ptr<State> state) : state_(std::move(state)) {}
EglContext::EglContext(EglContext&&) noexcept = default;
EglContext& EglContext::operator=(EglContext&&) noexcept = default;
EglContext::~EglContext() = default;

void EglContext::makeCurrent() const
{
    eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, state_->context);
}

bool EglContext::isCurrent() const
{
    return eglGetCurrentContext() == state_->context;
}

void EglContext::release() const
{
    eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

void* EglContext::keepDisplay(const ContextOptions& options)
{
    const EglContext context = create(options);
    retainDisplay(context.state_->display); // one user more than any context: never terminated
    return context.state_->display;
}

EglContext::Binding EglContext::Binding::current()
{
    return {eglGetCurrentDisplay(), eglGetCurrentSurface(EGL_DRAW), eglGetCurrentSurface(EGL_READ),
            eglGetCurrentContext()};
}

EglContext::Scope::Scope(const EglContext& context)
{
    if (context.isCurrent())
        return;
    previous_ = Binding::current();
    if (eglMakeCurrent(context.state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, context.state_->context) !=
        EGL_TRUE) {
        const EGLint error = eglGetError();
        throw ContextError(error == EGL_BAD_ACCESS
                               ? std::string("the EGL context is in use on another thread at the same time")
                               : fmt::format("eglMakeCurrent failed: {}", eglErrorName(error)));
    }
    context_ = &context;
}

EglContext::Scope::Scope(const EglContext& context, const Binding& before) : context_(&context), previous_(before) {}

EglContext::Scope::~Scope()
{
    if (!context_)
        return;
    if (previous_.context != EGL_NO_CONTEXT)
        eglMakeCurrent(previous_.display, previous_.draw, previous_.read, previous_.context);
    else
        eglMakeCurrent(context_->state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

} // namespace defocus::gl
