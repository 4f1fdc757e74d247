// SPDX-License-Identifier: LGPL-2.1-or-later
// Source selection for streams, called by openSource() before the file sources:
//   defocus /dev/video0 [--depth depth.png | depth_dir/ | depth.txt | /dev/video2]
//   defocus clip.mp4 --depth depth_dir/ | depth.txt            (depth image k for video frame k)
#pragma once

#include <memory>

#include "sources/FrameSource.hpp"

namespace defocus {

/// The source for a camera input (/dev/video*), or for a video file with a depth sequence; null
/// when `options` name neither, and openSource() goes on with the file sources. A camera given
/// as depth is read as a Z16 node paired by timestamp with the colour camera. Throws
/// SourceError like openSource(), e.g. for a depth camera without a colour camera.
std::unique_ptr<FrameSource> openStreamSource(const SourceOptions& options);

} // namespace defocus
