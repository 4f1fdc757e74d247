// SPDX-License-Identifier: LGPL-2.1-or-later
// What kind of renderer a GL_RENDERER string names, and the choices made from it: where depth
// prep runs and the presets' precision (TargetFormat::Auto), so that the pipeline, the bench and
// `defocus --info` say the same.
#pragma once

#include <string_view>

namespace defocus::gl {

/// Mesa's software renderers (llvmpipe, softpipe, the classic swrast), which run the GPU's work
/// on the CPU.
bool isSoftwareRenderer(std::string_view glRenderer);

/// Depth prep and the scene measurement on the GPU on this renderer, unless told otherwise:
/// DEFOCUS_DEPTH_PREP=gpu or cpu chooses on any renderer (tests and profiling; another value is
/// warned about and ignored); otherwise the GPU, but the CPU on a software renderer, where it is
/// faster: on llvmpipe 8.7 and 34 ms a 640x480 frame against 1.5 and 1.3 (each pass's wall time,
/// `defocus-bench --sizes 640x480 --versus-cpu-prep --finish-each-pass`), its fragment shaders
/// paying 15 ns a pixel and its compute shaders' barriers more (docs/benchmarks.md).
bool depthPrepOnGpu(std::string_view glRenderer);

/// The passes' fragment shaders run as compute shaders on this renderer, unless told otherwise:
/// DEFOCUS_PASSES=compute or fragment chooses on any renderer (tests and profiling; another value
/// is warned about and ignored); otherwise compute on a GPU, whose datacenter parts draw on a
/// few of their processing clusters and compute on all of them, and fragment on a software
/// renderer, where image stores cost more than a fragment's output (docs/benchmarks.md).
bool computePasses(std::string_view glRenderer);

/// The presets' precision on this renderer: half-float targets on a GPU, full float on a software
/// renderer, which converts half floats on every fetch and store.
inline bool halfFloatTargets(std::string_view glRenderer)
{
    return !isSoftwareRenderer(glRenderer);
}

} // namespace defocus::gl
