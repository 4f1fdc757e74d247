// SPDX-License-Identifier: LGPL-2.1-or-later
// Move-only RAII owners for GL objects. A default-constructed object is explicitly empty (id 0);
// moving leaves the source empty. Each object can carry a debug label (GL_KHR_debug).
#pragma once

#include <atomic>
#include <cstdint>
#include <string_view>
#include <utility>

#include <epoxy/gl.h>

namespace defocus::gl {

/// GL objects currently owned by Handles, all kinds together: flat over a long run means
/// nothing leaks (the soak test checks it).
inline std::atomic<long> liveObjects{0};

/// Shared ownership logic: `Deleter` frees one id.
template <void (*Deleter)(GLuint)>
class Handle {
public:
    Handle() = default;
    explicit Handle(GLuint id) : id_(id)
    {
        if (id_ != 0)
            ++liveObjects;
    }
    Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
    Handle& operator=(Handle&& other) noexcept
    {
        if (this != &other) {
            reset();
            id_ = std::exchange(other.id_, 0);
        }
        return *this;
    }
    Handle(const Handle&) = delete;
    Handle& operator=(const Handle&) = delete;
    ~Handle() { reset(); }

    GLuint id() const { return id_; }
    explicit operator bool() const { return id_ != 0; }
    void reset()
    {
        if (id_ != 0) {
            Deleter(std::exchange(id_, 0));
            --liveObjects;
        }
    }

private:
    GLuint id_ = 0;
};

void deleteTexture(GLuint id);
void deleteFramebuffer(GLuint id);
void deleteBuffer(GLuint id);
void deleteVertexArray(GLuint id);
void deleteSampler(GLuint id);
void deleteQuery(GLuint id);
void deleteProgram(GLuint id);

/// Waits until the GPU has passed `fence` (flushing first, then a second at a time) and deletes
/// it; nothing for a null fence. Counted in fenceWaits().
void waitAndDelete(GLsync& fence);

/// The CPU time the calling thread has used, milliseconds.
double threadCpuMs();

/// The calling thread's waits in waitAndDelete() since it started: how many, and the CPU time
/// they took (the flush that the first wait starts included). A driver that spins while it
/// waits (NVIDIA's yields in a loop unless told otherwise) charges the wait to the thread's CPU
/// time, so the bench reports it apart from the frame's own work.
struct FenceWaits {
    std::int64_t count = 0;
    double cpuMs = 0.0;
};
FenceWaits fenceWaits();

/// Adds the CPU time the calling thread spends in its scope, and one wait, to `into`.
class FenceWaitScope {
public:
    explicit FenceWaitScope(FenceWaits& into) : into_(into), start_(threadCpuMs()) {}
    ~FenceWaitScope()
    {
        into_.cpuMs += threadCpuMs() - start_;
        ++into_.count;
    }
    FenceWaitScope(const FenceWaitScope&) = delete;
    FenceWaitScope& operator=(const FenceWaitScope&) = delete;

private:
    FenceWaits& into_;
    double start_;
};

/// memcpy() of a frame's bytes to or from a mapped buffer, in stripes on OpenCV's threads where
/// it is large enough to pay for them: one core's memcpy does not reach the memory's bandwidth,
/// and the calling thread does only its share (a 1080p frame's is ~10 MB to go up, 6 to come back).
void copyFrameBytes(void* to, const void* from, std::size_t bytes);

/// Labels an object for GL debuggers and driver messages (no-op without GL_KHR_debug).
void label(GLenum identifier, GLuint id, std::string_view name);

/// An immutable-storage 2D texture (glTextureStorage2D) of one level.
class Texture {
public:
    Texture() = default;
    Texture(GLenum internalFormat, int width, int height, std::string_view name);
    /// A view of `of`'s image as `internalFormat`, of the same size and view class (GL_RGB8 of
    /// GL_SRGB8: the bytes without the sRGB decode). It holds the image; `of` may go first.
    static Texture view(const Texture& of, GLenum internalFormat, std::string_view name);

    GLuint id() const { return handle_.id(); }
    explicit operator bool() const { return bool(handle_); }
    GLenum format() const { return format_; }
    int width() const { return width_; }
    int height() const { return height_; }
    /// Replaces the whole image; `data` rows are tightly packed.
    void upload(GLenum format, GLenum type, const void* data);

private:
    Handle<deleteTexture> handle_;
    GLenum format_ = 0;
    int width_ = 0;
    int height_ = 0;
};

/// A framebuffer with one or two colour attachments: the render target of one pass.
class Framebuffer {
public:
    Framebuffer() = default;
    /// Attaches `texture` (not owned; must outlive this framebuffer).
    Framebuffer(const Texture& texture, std::string_view name);
    /// Attaches `first` and `second` as draw buffers 0 and 1 (outputs at locations 0 and 1);
    /// both of the same size, not owned.
    Framebuffer(const Texture& first, const Texture& second, std::string_view name);
    /// Attaches the 2D texture `texture` of `width` x `height` that a caller owns (not a Texture).
    Framebuffer(GLuint texture, int width, int height, std::string_view name);

    GLuint id() const { return handle_.id(); }
    explicit operator bool() const { return bool(handle_); }
    int width() const { return width_; }
    int height() const { return height_; }
    /// Binds for drawing and sets the viewport to the whole attachment.
    void bindForDraw() const;

    /// The attachments a compute shader stores into in place of drawing (0 for a caller's texture).
    int storeCount() const { return storeCount_; }
    /// Binds attachment i to image unit i, write-only (an sRGB one as its bytes: image stores
    /// cannot encode sRGB). Returns a bit per attachment the shader must encode as sRGB itself.
    unsigned bindForStore() const;

private:
    /// Records `texture` as attachment `index` for bindForStore().
    void addStore(int index, const Texture& texture, std::string_view name);

    Handle<deleteFramebuffer> handle_;
    int width_ = 0;
    int height_ = 0;
    struct Store {
        GLuint texture = 0;
        GLenum format = 0;
        bool srgb = false;
        Texture bytes; ///< an sRGB attachment's view as its bytes
    };
    Store stores_[2];
    int storeCount_ = 0;
};

/// A sampler object: filtering and edge clamping, separate from the texture.
class Sampler {
public:
    Sampler() = default;
    /// `wrap` addresses coordinates outside the texture: GL_CLAMP_TO_EDGE repeats the edge
    /// texels, GL_MIRRORED_REPEAT reflects the image about its edges.
    Sampler(GLenum filter, std::string_view name, GLenum wrap = GL_CLAMP_TO_EDGE);
    GLuint id() const { return handle_.id(); }

private:
    Handle<deleteSampler> handle_;
};

/// A uniform buffer sized for one C++ struct that mirrors a std140 GLSL block.
class UniformBuffer {
public:
    UniformBuffer() = default;
    UniformBuffer(GLsizeiptr size, std::string_view name);
    void update(const void* data, GLsizeiptr size);
    void bind(GLuint binding) const;
    GLuint id() const { return handle_.id(); }

private:
    Handle<deleteBuffer> handle_;
    GLsizeiptr size_ = 0;
};

/// A shader storage buffer of fixed size that compute shaders write and the CPU reads back.
class StorageBuffer {
public:
    StorageBuffer() = default;
    StorageBuffer(GLsizeiptr size, std::string_view name);
    GLsizeiptr size() const { return size_; }
    /// Replaces the first `bytes`.
    void update(const void* data, GLsizeiptr bytes);
    void bind(GLuint binding) const;
    GLuint id() const { return handle_.id(); }

private:
    Handle<deleteBuffer> handle_;
    GLsizeiptr size_ = 0;
};

/// A buffer that glReadPixels or a buffer copy fills behind a fence: the read is queued with the
/// frame's passes and returns at once; copyTo() waits for the fence (for the commands queued
/// before the read, not for those queued after it, as glGetBufferSubData may) and copies the
/// bytes out.
class ReadbackBuffer {
public:
    ReadbackBuffer() = default;
    ReadbackBuffer(GLsizeiptr size, std::string_view name);
    ~ReadbackBuffer();
    ReadbackBuffer(ReadbackBuffer&& other) noexcept;
    ReadbackBuffer& operator=(ReadbackBuffer&& other) noexcept;
    ReadbackBuffer(const ReadbackBuffer&) = delete;
    ReadbackBuffer& operator=(const ReadbackBuffer&) = delete;

    GLsizeiptr size() const { return size_; }
    /// Queues a read of the `width` x `height` pixels of `framebuffer`'s colour attachment as
    /// `format`/`type`, rows packed with no padding, and fences it. Needs width * height * pixel
    /// size <= size().
    void readPixels(GLuint framebuffer, int width, int height, GLenum format, GLenum type);
    /// Queues a copy of the first `bytes` of buffer `source` (written by shaders before a
    /// glMemoryBarrier with GL_BUFFER_UPDATE_BARRIER_BIT) and fences it. Needs bytes <= size().
    void readBuffer(GLuint source, GLsizeiptr bytes);
    /// Waits for the last readPixels() or readBuffer() and copies its first `bytes` into `data`.
    void copyTo(void* data, GLsizeiptr bytes);

private:
    void dropFence() noexcept;
    Handle<deleteBuffer> handle_;
    GLsizeiptr size_ = 0;
    GLsync fence_ = nullptr;
};

/// The empty vertex array that a full-screen triangle drawn from gl_VertexID needs in core GL.
class VertexArray {
public:
    VertexArray() = default;
    static VertexArray create();
    GLuint id() const { return handle_.id(); }

private:
    Handle<deleteVertexArray> handle_;
};

} // namespace defocus::gl
