// SPDX-License-Identifier: LGPL-2.1-or-later
// Tile instances: one ivec2 per tile in a vertex buffer, advanced once per instance.
#include "filter/passes/TileList.hpp"

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

} // namespace defocus
