#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
# A corpus turned a quarter turn, to check that an accuracy change does not depend on which way
# the scenes' edges run (railing-lights' bars stand upright; turned, they lie flat): every scene
# folder (scene.json) of each CORPUS_OR_SCENE_DIR is written to OUT/SCENE with its colour, depth
# and truth turned 90 degrees clockwise, the sensor width scaled by the new width over the old
# (the pixel pitch, and so every CoC in pixels, stays the same) and the blades turned with the
# image (-90 degrees, given as the least angle of the same polygon at or above 0: a hexagon's
# corner on top becomes a flat top, 30). Then
#   build/defocus-bench-accuracy --scene OUT --presets fast,balanced,high -o out/accuracy-turned
# measures it as the corpus is measured. Scenes with an aperture ratio other than 1 are left out
# (turned, the oval would need another lens, not only another ratio); the Blender scene is not a
# scene folder and is not turned. Needs NumPy and OpenCV's Python (python3-opencv).
#   scripts/corpus/turn.py [--out out/corpus-turned] data/corpus [data/corpus-apertures]
import argparse
import json
import os
import shutil
import sys

os.environ["OPENCV_IO_ENABLE_OPENEXR"] = "1"
import cv2  # noqa: E402

from corpusdirs import scene_dirs  # noqa: E402  (this folder)


def turned_rotation(degrees, blades):
    """Blade rotation - 90 degrees: for a polygon of N blades the same polygon's least rotation
    at or above 0 (modulo 360 / N); for the circle in [-180, 180]."""
    turned = degrees - 90.0
    if blades >= 3:
        return turned % (360.0 / blades)
    return turned + 360.0 if turned < -180.0 else turned


def turn(scene_dir, out_root):
    with open(os.path.join(scene_dir, "scene.json")) as f:
        scene = json.load(f)
    lens = scene["lens"]
    name = os.path.basename(os.path.normpath(scene_dir))
    if lens.get("apertureRatio", 1.0) != 1.0:
        print(f"turn.py: {name}: left out (aperture ratio {lens['apertureRatio']})")
        return False
    out = os.path.join(out_root, name)
    os.makedirs(out, exist_ok=True)
    width = None
    for key in ("color", "depth", "truth"):
        source = os.path.join(scene_dir, scene[key])
        image = cv2.imread(source, cv2.IMREAD_UNCHANGED)
        if image is None:
            sys.exit(f"turn.py: error: {source} does not read")
        if key == "color":
            width = image.shape[1]
        # Named by its own file name: a scene may take its images from another folder
        # (data/corpus-apertures/ takes colour and depth from data/corpus/).
        scene[key] = os.path.basename(scene[key])
        if not cv2.imwrite(os.path.join(out, scene[key]), cv2.rotate(image, cv2.ROTATE_90_CLOCKWISE)):
            sys.exit(f"turn.py: error: cannot write {os.path.join(out, scene[key])}")
        height = image.shape[0]
    lens["sensorWidthMm"] = lens["sensorWidthMm"] * height / width
    lens["bladeRotationDeg"] = turned_rotation(lens.get("bladeRotationDeg", 0.0), lens.get("blades", 6))
    scene["description"] = scene.get("description", "") + " Turned 90 degrees clockwise (scripts/corpus/turn.py)."
    with open(os.path.join(out, "scene.json"), "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")
    return True


def main():
    parser = argparse.ArgumentParser(description="A corpus turned 90 degrees clockwise")
    parser.add_argument("--out", default="out/corpus-turned", help="folder for the turned scenes (default %(default)s)")
    parser.add_argument("dirs", nargs="+", metavar="CORPUS_OR_SCENE_DIR")
    args = parser.parse_args()
    scenes = [d for path in args.dirs for d in scene_dirs(path, "turn.py")]
    if os.path.exists(args.out):
        shutil.rmtree(args.out)
    written = sum(turn(d, args.out) for d in scenes)
    print(f"turn.py: {written} scenes turned into {args.out}")


if __name__ == "__main__":
    main()
