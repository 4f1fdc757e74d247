#!/usr/bin/python3
# The anchors of the accuracy corpus: for every scene folder, Blender's Defocus compositor node
# (blender_defocus.py, calibrated) and GEGL's lens-blur driven by the thin-lens CoC of the
# scene's depth, written as ANCHORS/SCENE/{blender-defocus,gegl-lens-blur}.exr (linear) for
#   defocus-bench accuracy --scene ... --anchors ANCHORS
# Needs blender and gegl (Debian 12 packages; for measuring only, not to build defocus).
#   scripts/corpus/anchors.py [--out out/corpus_anchors] SCENE_OR_CORPUS_DIR...
import argparse
import json
import os
import subprocess
import sys
import time

os.environ["OPENCV_IO_ENABLE_OPENEXR"] = "1"
import cv2  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def scene_dirs(path):
    if os.path.isfile(os.path.join(path, "scene.json")):
        return [path]
    found = sorted(os.path.join(path, d) for d in os.listdir(path)
                   if os.path.isfile(os.path.join(path, d, "scene.json")))
    if not found:
        sys.exit(f"anchors.py: {path}: no scene.json in it or its subfolders")
    return found


def depth_metres(scene_dir, meta):
    image = cv2.imread(os.path.join(scene_dir, meta["depth"]), cv2.IMREAD_UNCHANGED)
    if image is None:
        sys.exit(f"anchors.py: cannot read {meta['depth']} in {scene_dir}")
    if image.ndim == 3:
        image = image[..., 0]
    if image.dtype == np.uint16:
        return image.astype(np.float32) / meta.get("depthUnitsPerMetre", 1000.0)
    return image.astype(np.float32)


def coc_px(depth, lens, width):
    """Signed thin-lens CoC diameter, pixels, field of view from the focal length (as Cycles and
    the benchmark's scenes): A f (S2 - S1) / (S2 (S1 - f)) on the sensor, mm, times px per mm."""
    f = lens["focalLengthMm"]
    aperture = f / lens["fNumber"]
    s1 = lens["focusM"] * 1000.0
    s2 = np.maximum(depth, 1e-3) * 1000.0
    if lens.get("fieldOfView", "focal-length") != "focal-length":
        sys.exit("anchors.py: only the focal-length field of view (the renders')")
    return aperture * f * (s2 - s1) / (s2 * (s1 - f)) * width / lens["sensorWidthMm"]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("paths", nargs="+")
    parser.add_argument("--out", default="out/corpus_anchors")
    args = parser.parse_args()
    for path in args.paths:
        for scene_dir in scene_dirs(path):
            name = os.path.basename(os.path.normpath(scene_dir))
            meta = json.load(open(os.path.join(scene_dir, "scene.json")))
            out = os.path.join(args.out, name)
            os.makedirs(out, exist_ok=True)
            colour = os.path.join(scene_dir, meta["color"])
            width = cv2.imread(colour, cv2.IMREAD_UNCHANGED).shape[1]
            coc = coc_px(depth_metres(scene_dir, meta), meta["lens"], width)
            radius = float(np.ceil(np.abs(coc).max() / 2.0)) + 1.0

            # GEGL: lens-blur's aux mask scales its radius per pixel (linear values 0..1).
            mask = os.path.join(out, "gegl_mask.exr")
            cv2.imwrite(mask, (np.abs(coc) / 2.0 / radius).astype(np.float32))
            start = time.time()
            target = os.path.join(out, "gegl-lens-blur.exr")
            subprocess.run(["nice", "-n", "19", "gegl", colour, "-o", target, "--", "gegl:lens-blur",
                            f"radius={radius}", "linear-mask=true", "clip=true",
                            "aux=[", "gegl:load", f"path={mask}", "]"], check=True)
            gegl_s = time.time() - start

            start = time.time()
            subprocess.run(["nice", "-n", "19", "blender", "-b", "--factory-startup", "--python",
                            os.path.join(HERE, "blender_defocus.py"), "--", scene_dir,
                            os.path.join(out, "blender-defocus.exr"), str(radius * 1.2)],
                           check=True, stdout=subprocess.DEVNULL)
            print(f"anchors.py: {name}: max CoC radius {radius:.0f} px; gegl {gegl_s:.1f} s, "
                  f"blender {time.time() - start:.1f} s")


main()
