// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus::Source: the command line's inputs as a stream of colour + depth frames, for programs
// that want to read what `defocus INPUT` reads (GStreamer's defocussrc is one).
//   defocus::Source source({"data/tum_fr1_rpy"});        // TUM folder: depth in metres, 5000 units/m
//   while (auto frame = source.next()) filter.process(*frame);
//
// Inputs, as the command line takes them: a TUM RGB-D folder (rgb.txt + depth.txt, files named by
// timestamp), a folder of colour images with `depth` a folder (paired by sorted name) or one file,
// one image with one depth image, a video file with a depth folder or TUM depth list (paired by
// index), and a V4L2 camera (/dev/videoN) with `depth` a depth image or a Z16 depth camera
// (/dev/videoM); or a synthetic scene (SourceSettings::synthetic).
// Threads: a Source is used from one thread at a time (any thread, one after another); only a
// synthetic scene has a GL context, made current on the calling thread for each call, as a Filter.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "defocus/Export.hpp"
#include "defocus/Filter.hpp"
#include "defocus/Frame.hpp"

namespace defocus {

/// A frame that cannot be read, or an input that does not exist or is not recognised: what()
/// is the command line's message, naming the file or device.
class DEFOCUS_API SourceReadError : public InputError {
public:
    using InputError::InputError;
};

/// A synthetic scene rendered frame by frame (docs/synthetic.md): the command line's --demo.
struct SyntheticClip {
    /// "spheres" (lights over depth edges) or "edges" (occlusion boundaries).
    std::string scene = "spheres";
    /// Clip length, frames, >= 1; the shot's animation spans it.
    std::size_t frames = 60;
    /// The camera: focal length, f-number, sensor width and blade rotation, and focusM on every
    /// frame unless focusPull.
    Lens lens;
    /// The focus follows the scene's own pull, which Source::sceneFocusM gives per frame.
    bool focusPull = true;
};

/// The scenes SyntheticClip::scene takes.
DEFOCUS_API std::vector<std::string> syntheticScenes();

struct SourceSettings {
    /// What `defocus INPUT` takes: a folder, an image, a video file or /dev/videoN. Not used
    /// where `synthetic` is set.
    std::string input;
    /// --depth: a folder, an image, a TUM depth list or a Z16 camera; empty where the input names
    /// its own depth (TUM) or has none (the frames pass through in focus).
    std::string depth;
    /// --depth-scale: units per metre of 16-bit depth images, > 0. Unset: 5000 for TUM folders
    /// and a TUM depth list, 1000 otherwise.
    std::optional<double> depthScale;
    /// 16-bit depth (PNG files, Z16 cameras) comes as it was stored: CV_16UC1 with
    /// Frame::depthScale its units per metre, for Filter::process to upload as it is (set
    /// Settings::depthScale to the same; half the bytes of metres, converted where the depth is
    /// prepared). Otherwise every frame's depth is CV_32FC1 metres.
    bool depthUnits = false;
    /// A colour camera's Y'CbCr frames (YUYV, NV12) come as they were captured: Frame::yuv holds
    /// their planes and Frame::color is empty, for Filter::process to upload as they are (half
    /// the bytes of BGR, converted on the GPU; colorBgr() gives BGR). Other inputs and formats
    /// come as BGR either way.
    bool yuvColor = false;
    /// A camera is asked for this size (pixels) and rate (Hz); it answers with the nearest it has.
    int width = 640;
    int height = 480;
    double fps = 30.0;
    /// Renders this scene instead of reading `input`: 640x480 CV_32FC3 scene-linear colour and
    /// exact depth, 30 Hz, with OpenGL on a context of the Source's own (on `context`'s device).
    std::optional<SyntheticClip> synthetic;
    ContextOptions context;
    /// A recorded clip's frames decoded ahead of next() on this many threads of the Source's own,
    /// several at once where the input allows (a TUM folder, a folder pair), in the clip's order,
    /// an error after the frames before it; 0: each frame read in next(). defaultReadThreads() is
    /// what the command line takes. A camera's frames are read when asked whatever this says.
    std::size_t readThreads = 0;
};

/// Threads for decoding a recorded clip ahead, where `clips` clips are read at once: the CPUs
/// this process may run on (its affinity: a Slurm job's or taskset's) less one, shared among the
/// clips, at most 8, at least one: the command line's --read-threads 0.
DEFOCUS_API std::size_t defaultReadThreads(std::size_t clips = 1);

/// One frame as the source gives it (the same type Filter::process takes apart).
using SourceFrame = Frame;

class DEFOCUS_API Source {
public:
    /// Opens the input; throws SourceReadError with the command line's message when it does not
    /// exist or cannot be recognised.
    explicit Source(const SourceSettings& settings);
    ~Source();
    Source(Source&&) noexcept;
    Source& operator=(Source&&) noexcept;
    Source(const Source&) = delete;
    Source& operator=(const Source&) = delete;

    /// The next frame; nullopt at the end. Throws SourceReadError when a frame cannot be read
    /// (a camera unplugged, a corrupt file); the stream may not be resumed after that.
    std::optional<SourceFrame> next();
    /// Frames in the input when known in advance (recorded inputs).
    std::optional<std::size_t> frameCount() const;
    /// Nominal rate, Hz; 0 when unknown.
    double frameRate() const;
    /// A camera (frames come in real time and do not end by themselves).
    bool isLive() const;
    /// A synthetic scene with its focus pull: the focus frame `index` was rendered for (what
    /// Lens::focusM must be to blur it as the camera would); nullopt for any other input.
    std::optional<double> sceneFocusM(std::size_t index) const;
    /// One line: kind, location and how colour meets depth, e.g. for the bundled clip
    /// "TUM RGB-D sequence 'data/tum_fr1_rpy' (10 frames, 10 with depth, paired by
    /// associations.txt, 30 Hz)".
    std::string describe() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace defocus
