// SPDX-License-Identifier: LGPL-2.1-or-later
// A set of 16x16 tiles to draw as instances with shaders/tiles.vert, so a pass can run on the
// tiles that need it and leave the others to a cheaper pass.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "filter/gl/Objects.hpp"

namespace defocus {

class TileList {
public:
    TileList();
    /// Replaces the tiles (column, row) of a target `targetSize` pixels large.
    void set(const std::vector<cv::Point>& tiles, cv::Size targetSize, int tileSize);
    int count() const { return count_; }
    /// Binds the tile parameters (uniform binding 1) and draws every tile; the program must use
    /// tiles.vert and the target must be bound.
    void draw() const;
    /// Binds the tile parameters and the tiles (storage binding 7) and dispatches a compute
    /// form of a program drawn with tiles.vert over every tile (gl::computeFormSource()).
    void dispatch() const;

private:
    struct Uniforms {
        float targetSize[2];
        float tileSize;
        float pad;
    };
    gl::Handle<gl::deleteBuffer> buffer_;
    gl::Handle<gl::deleteVertexArray> vao_;
    gl::UniformBuffer uniforms_;
    GLsizeiptr capacity_ = 0;
    int count_ = 0;
    int tileSize_ = 0;
};

} // namespace defocus
