// SPDX-License-Identifier: LGPL-2.1-or-later
// Texture uploads through a ring of persistently mapped pixel unpack buffers: the caller's
// pixels are copied into the next slot and the texture update is queued from there, so that the
// driver takes them from GPU-visible memory when the GPU gets to it, instead of copying (and, for
// 3-byte BGR, converting) them on the calling thread during the call. A slot is written again
// only once the GPU has read it (a fence per slot), a ring's length later.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "filter/gl/Objects.hpp"

namespace defocus::gl {

class UploadRing {
public:
    /// `slots` buffers, each grown to the largest upload it is given.
    UploadRing(std::size_t slots, std::string_view name);
    ~UploadRing();
    UploadRing(const UploadRing&) = delete;
    UploadRing& operator=(const UploadRing&) = delete;

    /// Replaces the whole image of `texture` with `data`, rows tightly packed, as `format` /
    /// `type` (what glTextureSubImage2D takes), `bytes` long.
    void upload(const Texture& texture, GLenum format, GLenum type, const void* data, std::size_t bytes);

private:
    struct Slot {
        Handle<deleteBuffer> buffer;
        void* mapped = nullptr;
        std::size_t size = 0;
        GLsync fence = nullptr; ///< the GPU's read of the slot's last upload
    };
    std::vector<Slot> slots_;
    std::size_t next_ = 0;
    std::string name_;
};

} // namespace defocus::gl
