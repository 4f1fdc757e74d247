#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
# Turns one scene's raw renders (scenes.py) into a corpus scene folder that
# `defocus-bench accuracy --scene DIR` reads, small enough to commit:
#   color_linear.exr  pinhole colour, scene-linear, half float (PIZ), mantissa rounded to 7 bits
#   depth_mm.png      planar depth, 16-bit millimetres
#   truth_linear.exr  thin-lens truth: the mean of the seed renders, stored the same way
# Rounding half's 10-bit mantissa to 7 bits (relative error at most 2^-8) takes each EXR from
# ~820 to ~490 KB; its error, 68-71 dB on overlapping-lights, is far below the truths' noise.
#   scene.json        the lens, the files, and how converged the truth is
# Convergence: two renders with different seeds have independent noise of variance s^2 each, so
# their MSE is 2 s^2 and the mean's noise is s^2 / 2 = MSE / 4: the truth is about
# PSNR(seed a, seed b) + 6.02 dB from the converged image (linear values clipped to [0, 1], the
# benchmark's measure; clipping makes this an estimate). Also given for the lights zone alone
# (within 30 px of a pinhole pixel above white), where nearly all of the noise is.
# A variant (scenes.py: BASE--APERTURE, the base's scene through another aperture) is assembled
# with --base BASE_SCENE_DIR: its folder holds only truth_linear.exr and a scene.json that names
# the base's colour and depth by their paths relative to it (the pinhole images are the base's).
#   scripts/corpus/assemble.py RAW_DIR OUT_DIR [--base BASE_SCENE_DIR]
import argparse
import glob
import json
import math
import os
import sys

os.environ["OPENCV_IO_ENABLE_OPENEXR"] = "1"
import cv2  # noqa: E402
import numpy as np  # noqa: E402

EXR_HALF = [cv2.IMWRITE_EXR_TYPE, cv2.IMWRITE_EXR_TYPE_HALF, cv2.IMWRITE_EXR_COMPRESSION,
            cv2.IMWRITE_EXR_COMPRESSION_PIZ]


def read(path):
    image = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if image is None:
        sys.exit(f"assemble.py: cannot read {path}")
    return image.astype(np.float32)


def rounded(image, bits=7):
    """Half float with the mantissa rounded to `bits` bits (of 10), back as float32."""
    half = image.astype(np.float16).view(np.uint16).astype(np.uint32)
    drop = 10 - bits
    half = ((half + (1 << (drop - 1))) >> drop) << drop
    return half.astype(np.uint16).view(np.float16).astype(np.float32)


def psnr_clipped(a, b):
    mse = float(np.mean((np.clip(a, 0, 1) - np.clip(b, 0, 1)) ** 2))
    return math.inf if mse == 0 else -10 * math.log10(mse)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("raw")
    parser.add_argument("out")
    parser.add_argument("--base", help="a variant's base scene folder: its colour and depth are used, not copied")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    meta = json.load(open(os.path.join(args.raw, "lens.json")))
    lens = meta["lens"]
    render = json.load(open(os.path.join(args.raw, "render.json"))) if os.path.exists(
        os.path.join(args.raw, "render.json")) else {}

    if args.base:
        base = json.load(open(os.path.join(args.base, "scene.json")))
        base_lens = {k: v for k, v in base["lens"].items() if k not in ("blades", "bladeRotationDeg", "apertureRatio")}
        own_lens = {k: v for k, v in lens.items() if k not in ("blades", "bladeRotationDeg", "apertureRatio")}
        if base_lens != own_lens:
            sys.exit(f"assemble.py: {args.raw}: lens {own_lens} is not the base's {base_lens} but for the aperture")
        colour = read(os.path.join(args.base, base["color"]))
        # The pinhole is the base's: its files, named relative to the variant's folder.
        color_path = os.path.relpath(os.path.join(args.base, base["color"]), args.out)
        depth_path = os.path.relpath(os.path.join(args.base, base["depth"]), args.out)
        depth_units = base.get("depthUnitsPerMetre", 1000)
        render["pinholeSamples"] = base["render"].get("pinholeSamples")
    else:
        colour = read(os.path.join(args.raw, "color_linear.exr"))
        depth = read(os.path.join(args.raw, "depth.exr"))
        if depth.ndim == 3:
            depth = depth[..., 0]
        if depth.max() * 1000 > 65535:
            sys.exit(f"assemble.py: {args.raw}: depth reaches {depth.max():.1f} m, beyond 65.535 m of 16-bit mm")
        color_path, depth_path, depth_units = "color_linear.exr", "depth_mm.png", 1000
    seeds = sorted(glob.glob(os.path.join(args.raw, "truth_seed*.exr")))
    if len(seeds) < 2:
        sys.exit(f"assemble.py: {args.raw}: need at least two truth_seed*.exr renders, found {len(seeds)}")
    halves = [read(s) for s in seeds]
    truth = np.mean(halves, axis=0)
    pair_db = psnr_clipped(halves[0], halves[1])
    # MSE(a, b) = 2 s^2, so one seed is PSNR(a, b) + 3.01 dB from converged, and the mean of k
    # seeds (noise s^2 / k) another 10 log10(k) dB better.
    truth_db = pair_db + 10 * math.log10(2) + 10 * math.log10(len(halves))

    not_light = (colour.max(axis=2) <= 1.0).astype(np.uint8)
    outside = cv2.distanceTransform(not_light, cv2.DIST_L2, cv2.DIST_MASK_PRECISE) > 30.0
    outside_db = psnr_clipped(halves[0][outside], halves[1][outside]) + 10 * math.log10(2 * len(halves))

    if not args.base:
        if not cv2.imwrite(os.path.join(args.out, "color_linear.exr"), rounded(colour), EXR_HALF):
            sys.exit("assemble.py: cannot write color_linear.exr")
        mm = np.clip(np.round(depth * 1000.0), 0, 65535).astype(np.uint16)
        if not cv2.imwrite(os.path.join(args.out, "depth_mm.png"), mm, [cv2.IMWRITE_PNG_COMPRESSION, 9]):
            sys.exit("assemble.py: cannot write depth_mm.png")
    if not cv2.imwrite(os.path.join(args.out, "truth_linear.exr"), rounded(truth), EXR_HALF):
        sys.exit("assemble.py: cannot write truth_linear.exr")
    scene = {
        "description": meta["description"],
        "color": color_path,
        "depth": depth_path,
        "depthUnitsPerMetre": depth_units,
        "truth": "truth_linear.exr",
        "lens": lens,
        "render": {
            "renderer": "Blender 3.4 Cycles (CPU), scripts/corpus/scenes.py",
            "pinholeSamples": render.get("pinholeSamples"),
            "truthSeeds": len(halves),
            "truthSamplesPerSeed": render.get("truthSamplesPerSeed"),
            "truthAdaptive": render.get("truthAdaptive", ""),
            "seedPairPsnrDb": round(pair_db, 2),
            "truthEstimatedPsnrDb": round(truth_db, 2),
            "truthEstimatedPsnrDbOutsideLights": round(outside_db, 2),
        },
    }
    # Seconds each seed's render took (render.sh: niced, wall clock), where it noted them.
    seconds = [os.path.splitext(s)[0] + ".seconds" for s in seeds]
    if all(os.path.exists(s) for s in seconds):
        scene["render"]["truthSecondsPerSeed"] = [int(open(s).read()) for s in seconds]
    with open(os.path.join(args.out, "scene.json"), "w") as f:
        json.dump(scene, f, indent=2)
        f.write("\n")
    print(f"assemble.py: {args.out}: truth from {len(halves)} seeds, seeds agree to {pair_db:.2f} dB, "
          f"truth about {truth_db:.2f} dB from converged ({outside_db:.2f} outside the lights)"
          + ("" if args.base else f"; depth {depth.min():.2f}-{depth.max():.2f} m"))


main()
