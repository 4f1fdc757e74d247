// SPDX-License-Identifier: LGPL-2.1-or-later
// Texture uploads through persistently mapped pixel unpack buffers, fenced per slot.
#include "filter/gl/UploadRing.hpp"

#include <stdexcept>

namespace defocus::gl {

UploadRing::UploadRing(std::size_t slots, std::string_view name) : slots_(slots), name_(name) {}

UploadRing::~UploadRing()
{
    for (Slot& slot : slots_)
        if (slot.fence != nullptr)
            glDeleteSync(slot.fence);
}

void UploadRing::upload(const Texture& texture, GLenum format, GLenum type, const void* data, std::size_t bytes)
{
    Slot& slot = slots_[next_];
    next_ = (next_ + 1) % slots_.size();
    waitAndDelete(slot.fence); // the GPU has read the slot's last upload
    if (slot.size < bytes) {
        // Coherent: what the CPU writes is visible to the GPU's next command, with no flush.
        constexpr GLbitfield kFlags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
        GLuint id = 0;
        glCreateBuffers(1, &id);
        slot.buffer = Handle<deleteBuffer>(id);
        glNamedBufferStorage(id, static_cast<GLsizeiptr>(bytes), nullptr, kFlags);
        slot.mapped = glMapNamedBufferRange(id, 0, static_cast<GLsizeiptr>(bytes), kFlags);
        if (slot.mapped == nullptr)
            throw std::runtime_error("glMapNamedBufferRange failed on an upload buffer");
        slot.size = bytes;
        label(GL_BUFFER, id, name_);
    }
    copyFrameBytes(slot.mapped, data, bytes);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, slot.buffer.id());
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(texture.id(), 0, 0, 0, texture.width(), texture.height(), format, type, nullptr);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    slot.fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
}

} // namespace defocus::gl
