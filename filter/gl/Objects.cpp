// SPDX-License-Identifier: LGPL-2.1-or-later
// RAII GL object wrappers: creation with DSA (GL 4.5), deletion, debug labels.
#include "filter/gl/Objects.hpp"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <ctime>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <opencv2/core/utility.hpp>

namespace defocus::gl {

void deleteTexture(GLuint id) { glDeleteTextures(1, &id); }

namespace {
thread_local FenceWaits gFenceWaits;
}

double threadCpuMs()
{
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

FenceWaits fenceWaits() { return gFenceWaits; }

void waitAndDelete(GLsync& fence)
{
    if (fence == nullptr)
        return;
    const FenceWaitScope scope(gFenceWaits);
    // The first wait flushes; later ones wait a second at a time.
    GLbitfield flags = GL_SYNC_FLUSH_COMMANDS_BIT;
    while (glClientWaitSync(fence, flags, 1'000'000'000) == GL_TIMEOUT_EXPIRED)
        flags = 0;
    glDeleteSync(fence);
    fence = nullptr;
}
void copyFrameBytes(void* to, const void* from, std::size_t bytes)
{
    // Stripes of 1 MiB: below two of them, the threads' start costs more than they save.
    constexpr std::size_t kStripe = std::size_t{1} << 20;
    if (bytes < 2 * kStripe) {
        std::memcpy(to, from, bytes);
        return;
    }
    auto* out = static_cast<unsigned char*>(to);
    const auto* in = static_cast<const unsigned char*>(from);
    const auto stripes = static_cast<int>((bytes + kStripe - 1) / kStripe);
    cv::parallel_for_(cv::Range(0, stripes), [&](const cv::Range& range) {
        const std::size_t begin = static_cast<std::size_t>(range.start) * kStripe;
        const std::size_t end = std::min(bytes, static_cast<std::size_t>(range.end) * kStripe);
        std::memcpy(out + begin, in + begin, end - begin);
    });
}

void deleteFramebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void deleteBuffer(GLuint id) { glDeleteBuffers(1, &id); }
void deleteVertexArray(GLuint id) { glDeleteVertexArrays(1, &id); }
void deleteSampler(GLuint id) { glDeleteSamplers(1, &id); }
void deleteQuery(GLuint id) { glDeleteQueries(1, &id); }
void deleteProgram(GLuint id) { glDeleteProgram(id); }

void label(GLenum identifier, GLuint id, std::string_view name)
{
    if (epoxy_has_gl_extension("GL_KHR_debug"))
        glObjectLabel(identifier, id, static_cast<GLsizei>(name.size()), name.data());
}

Texture::Texture(GLenum internalFormat, int width, int height, std::string_view name)
    : format_(internalFormat), width_(width), height_(height)
{
    assert(width > 0 && height > 0);
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &id);
    handle_ = Handle<deleteTexture>(id);
    glTextureStorage2D(id, 1, internalFormat, width, height);
    label(GL_TEXTURE, id, name);
}

Texture Texture::view(const Texture& of, GLenum internalFormat, std::string_view name)
{
    assert(of);
    Texture texture;
    GLuint id = 0;
    glGenTextures(1, &id); // a view's name must not have been bound yet
    texture.handle_ = Handle<deleteTexture>(id);
    glTextureView(id, GL_TEXTURE_2D, of.id(), internalFormat, 0, 1, 0, 1);
    label(GL_TEXTURE, id, name);
    texture.format_ = internalFormat;
    texture.width_ = of.width_;
    texture.height_ = of.height_;
    return texture;
}

void Texture::upload(GLenum format, GLenum type, const void* data)
{
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(id(), 0, 0, 0, width_, height_, format, type, data);
}

Framebuffer::Framebuffer(const Texture& texture, std::string_view name)
    : width_(texture.width()), height_(texture.height())
{
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    handle_ = Handle<deleteFramebuffer>(id);
    glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0, texture.id(), 0);
    label(GL_FRAMEBUFFER, id, name);
    addStore(0, texture, name);
}

Framebuffer::Framebuffer(const Texture& first, const Texture& second, std::string_view name)
    : width_(first.width()), height_(first.height())
{
    assert(first.width() == second.width() && first.height() == second.height());
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    handle_ = Handle<deleteFramebuffer>(id);
    glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0, first.id(), 0);
    glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT1, second.id(), 0);
    const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(id, 2, buffers);
    label(GL_FRAMEBUFFER, id, name);
    addStore(0, first, name);
    addStore(1, second, name);
}

Framebuffer::Framebuffer(GLuint texture, int width, int height, std::string_view name)
    : width_(width), height_(height)
{
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    handle_ = Handle<deleteFramebuffer>(id);
    glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0, texture, 0);
    label(GL_FRAMEBUFFER, id, name);
}

void Framebuffer::bindForDraw() const
{
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, id());
    glViewport(0, 0, width_, height_);
}

void Framebuffer::addStore(int index, const Texture& texture, std::string_view name)
{
    Store& store = stores_[index];
    store.texture = texture.id();
    store.format = texture.format();
    store.srgb = texture.format() == GL_SRGB8_ALPHA8;
    if (store.srgb) {
        store.bytes = Texture::view(texture, GL_RGBA8, fmt::format("{}, bytes", name));
        store.texture = store.bytes.id();
        store.format = GL_RGBA8;
    }
    storeCount_ = index + 1;
}

unsigned Framebuffer::bindForStore() const
{
    unsigned srgb = 0;
    for (int i = 0; i < storeCount_; ++i) {
        glBindImageTexture(static_cast<GLuint>(i), stores_[i].texture, 0, GL_FALSE, 0, GL_WRITE_ONLY, stores_[i].format);
        srgb |= stores_[i].srgb ? 1u << i : 0u;
    }
    return srgb;
}

Sampler::Sampler(GLenum filter, std::string_view name, GLenum wrap)
{
    GLuint id = 0;
    glCreateSamplers(1, &id);
    handle_ = Handle<deleteSampler>(id);
    glSamplerParameteri(id, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
    glSamplerParameteri(id, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
    glSamplerParameteri(id, GL_TEXTURE_WRAP_S, static_cast<GLint>(wrap));
    glSamplerParameteri(id, GL_TEXTURE_WRAP_T, static_cast<GLint>(wrap));
    label(GL_SAMPLER, id, name);
}

UniformBuffer::UniformBuffer(GLsizeiptr size, std::string_view name) : size_(size)
{
    GLuint id = 0;
    glCreateBuffers(1, &id);
    handle_ = Handle<deleteBuffer>(id);
    glNamedBufferStorage(id, size, nullptr, GL_DYNAMIC_STORAGE_BIT);
    label(GL_BUFFER, id, name);
}

void UniformBuffer::update(const void* data, GLsizeiptr size)
{
    assert(size <= size_);
    glNamedBufferSubData(id(), 0, size, data);
}

void UniformBuffer::bind(GLuint binding) const
{
    glBindBufferBase(GL_UNIFORM_BUFFER, binding, id());
}

StorageBuffer::StorageBuffer(GLsizeiptr size, std::string_view name) : size_(size)
{
    GLuint id = 0;
    glCreateBuffers(1, &id);
    handle_ = Handle<deleteBuffer>(id);
    glNamedBufferStorage(id, size, nullptr, GL_DYNAMIC_STORAGE_BIT);
    label(GL_BUFFER, id, name);
}

void StorageBuffer::update(const void* data, GLsizeiptr bytes)
{
    assert(bytes <= size_);
    glNamedBufferSubData(id(), 0, bytes, data);
}

void StorageBuffer::bind(GLuint binding) const
{
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, id());
}

ReadbackBuffer::ReadbackBuffer(GLsizeiptr size, std::string_view name) : size_(size)
{
    GLuint id = 0;
    glCreateBuffers(1, &id);
    handle_ = Handle<deleteBuffer>(id);
    glNamedBufferStorage(id, size, nullptr, GL_MAP_READ_BIT | GL_CLIENT_STORAGE_BIT);
    label(GL_BUFFER, id, name);
}

ReadbackBuffer::~ReadbackBuffer()
{
    dropFence();
}

ReadbackBuffer::ReadbackBuffer(ReadbackBuffer&& other) noexcept
    : handle_(std::move(other.handle_)), size_(std::exchange(other.size_, 0)), fence_(std::exchange(other.fence_, nullptr))
{
}

ReadbackBuffer& ReadbackBuffer::operator=(ReadbackBuffer&& other) noexcept
{
    if (this != &other) {
        dropFence();
        handle_ = std::move(other.handle_);
        size_ = std::exchange(other.size_, 0);
        fence_ = std::exchange(other.fence_, nullptr);
    }
    return *this;
}

void ReadbackBuffer::dropFence() noexcept
{
    if (fence_ != nullptr)
        glDeleteSync(std::exchange(fence_, nullptr));
}

void ReadbackBuffer::readPixels(GLuint framebuffer, int width, int height, GLenum format, GLenum type)
{
    dropFence();
    glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, handle_.id());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, format, type, nullptr);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    fence_ = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush(); // the read starts now, not when the next frame's commands push it out
}

void ReadbackBuffer::readBuffer(GLuint source, GLsizeiptr bytes)
{
    assert(bytes <= size_);
    dropFence();
    glCopyNamedBufferSubData(source, handle_.id(), 0, 0, bytes);
    fence_ = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
}

void ReadbackBuffer::copyTo(void* data, GLsizeiptr bytes)
{
    assert(bytes <= size_);
    waitAndDelete(fence_);
    const void* mapped = glMapNamedBufferRange(handle_.id(), 0, bytes, GL_MAP_READ_BIT);
    if (mapped == nullptr)
        throw std::runtime_error("glMapNamedBufferRange failed on a readback buffer");
    copyFrameBytes(data, mapped, static_cast<std::size_t>(bytes));
    glUnmapNamedBuffer(handle_.id());
}

VertexArray VertexArray::create()
{
    GLuint id = 0;
    glCreateVertexArrays(1, &id);
    VertexArray vao;
    vao.handle_ = Handle<deleteVertexArray>(id);
    return vao;
}

} // namespace defocus::gl
