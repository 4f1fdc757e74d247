// SPDX-License-Identifier: LGPL-2.1-or-later
// Tile instances: one ivec2 per tile in a vertex buffer, advanced once per instance.
#include "filter/passes/TileList.hpp"

#include <algorithm>

namespace defocus {

TileList::TileList() : uniforms_(sizeof(Uniforms), "tile params")
{
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    vao_ = gl::Handle<gl::deleteVertexArray>(vao);
    glEnableVertexArrayAttrib(vao, 0);
    glVertexArrayAttribIFormat(vao, 0, 2, GL_INT, 0);
    glVertexArrayAttribBinding(vao, 0, 0);
    glVertexArrayBindingDivisor(vao, 0, 1);
}

void TileList::set(const std::vector<cv::Point>& tiles, cv::Size targetSize, int tileSize)
{
    static_assert(sizeof(cv::Point) == 2 * sizeof(GLint));
    count_ = static_cast<int>(tiles.size());
    const auto bytes = static_cast<GLsizeiptr>(tiles.size() * sizeof(cv::Point));
    if (bytes > capacity_) {
        GLuint id = 0;
        glCreateBuffers(1, &id);
        buffer_ = gl::Handle<gl::deleteBuffer>(id);
        glNamedBufferStorage(id, bytes, nullptr, GL_DYNAMIC_STORAGE_BIT);
        glVertexArrayVertexBuffer(vao_.id(), 0, id, 0, sizeof(cv::Point));
        capacity_ = bytes;
    }
    if (bytes > 0)
        glNamedBufferSubData(buffer_.id(), 0, bytes, tiles.data());
    tileSize_ = tileSize;
    const Uniforms u{{static_cast<float>(targetSize.width), static_cast<float>(targetSize.height)},
                     static_cast<float>(tileSize), 0.0f};
    uniforms_.update(&u, sizeof u);
}

void TileList::draw() const
{
    if (count_ == 0)
        return;
    GLint previous = 0;
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &previous);
    uniforms_.bind(1);
    glBindVertexArray(vao_.id());
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, count_);
    glBindVertexArray(static_cast<GLuint>(previous));
}

void TileList::dispatch() const
{
    if (count_ == 0)
        return;
    uniforms_.bind(1);
    // The range of this frame's tiles: the shader's computeTiles.length() is their count.
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 7, buffer_.id(), 0,
                      static_cast<GLsizeiptr>(count_) * static_cast<GLsizeiptr>(sizeof(cv::Point)));
    // One work group per 8x8 block of a tile; tiles in rows of at most 65535 (the least
    // GL_MAX_COMPUTE_WORK_GROUP_COUNT a driver may have), then layers of such rows.
    constexpr int kRows = 65535;
    const int blocksPerRow = (tileSize_ + 7) / 8;
    glDispatchCompute(static_cast<GLuint>(blocksPerRow * blocksPerRow), static_cast<GLuint>(std::min(count_, kRows)),
                      static_cast<GLuint>((count_ + kRows - 1) / kRows));
}

} // namespace defocus
