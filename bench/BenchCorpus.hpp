// SPDX-License-Identifier: LGPL-2.1-or-later
// The accuracy benchmark over scene folders (`defocus-bench accuracy --scene DIR ...`): every
// preset on every scene of a corpus, PSNR per scene and per zone (lights, depth edges, in focus,
// near, far), the minimum and the median per preset, and the anchors (Blender's Defocus node,
// GEGL's lens blur) where their outputs are given. docs/accuracy.md shows its output.
#pragma once

#include <string>
#include <vector>

namespace defocus {

struct CorpusOptions {
    std::vector<std::string> scenes; ///< scene folders or corpus folders (findAccuracyScenes())
    std::string out = "out/accuracy"; ///< corpus.json and corpus.csv go here
    /// Folder of anchor outputs, ANCHORS/SCENE/NAME.exr (linear), measured like the presets;
    /// empty: none. scripts/corpus/anchors.sh makes them.
    std::string anchors;
    bool missingOk = false;  ///< a --scene folder that does not exist: exit 77 (skipped), not 1
    bool saveOutputs = false; ///< also every preset's result, OUT/outputs/SCENE/PRESET.exr
    /// Names of the presets to run; empty: all. NAME:quarter is the preset with quarter size on
    /// large blur on (MethodSettings::quarterOnLargeBlur), NAME:half-only with it off (the presets'
    /// own setting), to compare the two in one run;
    /// NAME:no-sprites the preset without bokeh sprites (lights gathered like any pixel), as a
    /// frame the plan gives no sprites runs; the two combine.
    std::vector<std::string> presets;
    /// Every scene enlarged by this factor before it is measured: colour and truth bilinear,
    /// depth nearest, the lens unchanged, so that the CoC in pixels grows with the size (a
    /// 640x480 scene at 3 stands for 1920x1440). 1: as it is.
    int scale = 1;
};

/// Exit status: 0 done, 1 runtime failure (a bad scene folder, output), 77 skipped (a
/// missing scene folder with missingOk); errors it throws the caller maps (75 for no GL). Results on
/// stdout, one error line on stderr.
int runCorpusAccuracy(const CorpusOptions& options, const std::string& commandLine);

} // namespace defocus
