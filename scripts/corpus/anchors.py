#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
# The anchors of the accuracy corpus: for every scene folder, Blender's Defocus compositor node
# (blender_defocus.py, calibrated) and GEGL's lens-blur driven by the thin-lens CoC of the
# scene's depth, written as ANCHORS/SCENE/{blender-defocus,gegl-lens-blur}.exr (linear) for
#   defocus-bench accuracy --scene ... --anchors ANCHORS
# Both get the CoC of the truth's camera (thinlens.py, the filter's thin-lens model). Needs blender
# and gegl (Debian 12 packages; for measuring only, not to build defocus), or only the one named
# with --tool.
# Apertures (data/corpus-apertures/): Blender's node draws the scene's blades where it has them
# (disk, 3 to 8 blades; 9 to 11 get its octagon, 12 and more its disk) at the orientation of Cycles' bokeh behind the
# focus, and no aperture ratio (blender_defocus.py); GEGL's lens-blur draws a disk whatever the
# aperture.
#   scripts/corpus/anchors.py [--out out/corpus_anchors] [--tool gegl|blender] SCENE_OR_CORPUS_DIR...
#   scripts/corpus/anchors.py data/corpus-apertures        # the aperture variants
import argparse
import json
import os
import subprocess
import sys
import time

os.environ["OPENCV_IO_ENABLE_OPENEXR"] = "1"
import cv2  # noqa: E402
import numpy as np  # noqa: E402

from corpusdirs import scene_dirs  # noqa: E402  (this folder)
from thinlens import coc_px  # noqa: E402  (this folder: the filter's thin-lens CoC)

HERE = os.path.dirname(os.path.abspath(__file__))
TOOLS = ["gegl", "blender"]


def depth_metres(scene_dir, meta):
    image = cv2.imread(os.path.join(scene_dir, meta["depth"]), cv2.IMREAD_UNCHANGED)
    if image is None:
        sys.exit(f"anchors.py: cannot read {meta['depth']} in {scene_dir}")
    if image.ndim == 3:
        image = image[..., 0]
    if image.dtype == np.uint16:
        return image.astype(np.float32) / meta.get("depthUnitsPerMetre", 1000.0)
    return image.astype(np.float32)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("paths", nargs="+")
    parser.add_argument("--out", default="out/corpus_anchors")
    parser.add_argument("--tool", action="append", choices=TOOLS,
                        help="run only this tool (repeatable; default: both)")
    args = parser.parse_args()
    tools = args.tool or TOOLS
    for path in args.paths:
        for scene_dir in scene_dirs(path, "anchors.py"):
            name = os.path.basename(os.path.normpath(scene_dir))
            meta = json.load(open(os.path.join(scene_dir, "scene.json")))
            if meta["lens"].get("fieldOfView") != "focal-length":
                # Blender's node is calibrated for the renders' camera (blender_defocus.py).
                sys.exit(f"anchors.py: {scene_dir}/scene.json: lens.fieldOfView must be focal-length "
                         "(the renders' camera)")
            out = os.path.join(args.out, name)
            os.makedirs(out, exist_ok=True)
            colour = os.path.join(scene_dir, meta["color"])
            width = cv2.imread(colour, cv2.IMREAD_UNCHANGED).shape[1]
            coc = coc_px(np.maximum(depth_metres(scene_dir, meta), 1e-3), meta["lens"], width)
            radius = float(np.ceil(np.abs(coc).max() / 2.0)) + 1.0

            timings = []
            if "gegl" in tools:
                # GEGL: lens-blur's aux mask scales its radius per pixel (linear values 0..1).
                mask = os.path.join(out, "gegl_mask.exr")
                cv2.imwrite(mask, (np.abs(coc) / 2.0 / radius).astype(np.float32))
                start = time.time()
                target = os.path.join(out, "gegl-lens-blur.exr")
                subprocess.run(["nice", "-n", "19", "gegl", colour, "-o", target, "--", "gegl:lens-blur",
                                f"radius={radius}", "linear-mask=true", "clip=true",
                                "aux=[", "gegl:load", f"path={mask}", "]"], check=True)
                timings.append(f"gegl {time.time() - start:.1f} s")

            if "blender" in tools:
                start = time.time()
                done = subprocess.run(["nice", "-n", "19", "blender", "-b", "--factory-startup",
                                       "--python-exit-code", "1", "--python",
                                       os.path.join(HERE, "blender_defocus.py"), "--", scene_dir,
                                       os.path.join(out, "blender-defocus.exr"), str(radius * 1.2)],
                                      check=True, stdout=subprocess.PIPE, text=True)
                said = [line for line in done.stdout.splitlines() if line.startswith("blender_defocus.py:")]
                timings.append(f"blender {time.time() - start:.1f} s" + (f" ({said[-1][20:]})" if said else ""))
            lens = meta["lens"]
            aperture = ("disk" if lens.get("blades", 6) == 0 else f"{lens.get('blades', 6)} blades") + (
                f" at {lens.get('bladeRotationDeg', 0.0):g} deg" if lens.get("blades", 6) else "") + (
                f", ratio {lens['apertureRatio']:g} (neither tool has one)" if lens.get("apertureRatio", 1.0) != 1.0 else "")
            print(f"anchors.py: {name}: {aperture}; max CoC radius {radius:.0f} px; " + ", ".join(timings))


if __name__ == "__main__":
    main()
