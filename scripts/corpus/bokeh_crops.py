#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
# The lights' bokeh of corpus truths, to look at and to measure: which way an aperture points in
# front of the focus and behind it. For every light of a scene's pinhole (a blob above white),
# its truth's bokeh is cropped (sRGB, exposed for the bokeh, enlarged) and measured:
#   corners   for n blades, the direction of the n-th angular harmonic of the bokeh's shape
#             (where the bokeh reaches furthest from its centre), degrees counter-clockwise from
#             +x with y up, modulo 360/n
#   elongation for any aperture: the ratio of the shape's extents along its principal axes and
#             the direction of the longer one
# Writes OUT/SCENE/<light>.png (the truth, exposed for the bokeh, beside the silhouette measured)
# and OUT/SCENE/sheet.png (all of a scene's lights, one under another), and with several scenes
# of one base OUT/<base>-<light>.png: that light through every aperture, side by side.
#   scripts/corpus/bokeh_crops.py [--out out/corpus_bokeh] SCENE_DIR...
import argparse
import cmath
import json
import math
import os
import sys

os.environ["OPENCV_IO_ENABLE_OPENEXR"] = "1"
import cv2  # noqa: E402
import numpy as np  # noqa: E402

from thinlens import coc_px  # noqa: E402

ZOOM_TO = 200  # px, each crop's enlarged side


def read(scene_dir, name):
    image = cv2.imread(os.path.join(scene_dir, name), cv2.IMREAD_UNCHANGED)
    if image is None:
        sys.exit(f"bokeh_crops.py: cannot read {name} in {scene_dir}")
    return image


def srgb(linear):
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1 / 2.4) - 0.055)


def lights(colour, depth_m, lens):
    """(x, y, depth m, signed CoC px) of every blob of the pinhole above white."""
    bright = (colour.max(axis=2) > 1.0).astype(np.uint8)
    count, _, stats, centroids = cv2.connectedComponentsWithStats(bright)
    found = []
    for i in range(1, count):
        x, y = centroids[i]
        d = float(depth_m[int(round(y)), int(round(x))])
        found.append((float(x), float(y), d, float(coc_px(d, lens, colour.shape[1]))))
    return found


def measure(luma, blades):
    """Corner direction (n blades) and elongation of the bokeh around the crop's centre, and its
    silhouette (the mask measured)."""
    h, w = luma.shape
    cy, cx = (h - 1) / 2, (w - 1) / 2
    yy, xx = np.mgrid[0:h, 0:w]
    smooth = cv2.GaussianBlur(luma, (0, 0), 1.0)  # the truths' noise, on point lights above all
    centre = smooth[(xx - cx) ** 2 + (yy - cy) ** 2 <= (0.2 * w) ** 2]
    mask = (smooth > 0.5 * float(np.mean(centre))).astype(np.uint8)
    _, labels = cv2.connectedComponents(mask)
    mask = labels == labels[int(round(cy)), int(round(cx))]
    x, y = xx[mask].astype(float), -yy[mask].astype(float)  # y up
    x -= x.mean()
    y -= y.mean()
    r2 = x * x + y * y
    theta = np.arctan2(y, x)
    result = {"pixels": int(mask.sum())}
    if blades >= 3:
        harmonic = complex(np.sum(r2 * np.exp(1j * blades * theta)))
        result["cornersDeg"] = round(math.degrees(cmath.phase(harmonic)) / blades % (360.0 / blades), 1)
        result["harmonicStrength"] = round(abs(harmonic) / float(np.sum(r2)), 3)
    cov = np.cov(np.stack([x, y]))
    values, vectors = np.linalg.eigh(cov)
    result["elongation"] = round(math.sqrt(values[1] / values[0]), 2)
    result["longAxisDeg"] = round(math.degrees(math.atan2(vectors[1, 1], vectors[0, 1])) % 180.0, 1)
    return result, mask


def crop(image, x, y, half):
    h, w = image.shape[:2]
    x0, y0 = int(round(x)) - half, int(round(y)) - half
    if x0 < 0 or y0 < 0 or x0 + 2 * half + 1 > w or y0 + 2 * half + 1 > h:
        return None
    return image[y0:y0 + 2 * half + 1, x0:x0 + 2 * half + 1]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("scenes", nargs="+")
    parser.add_argument("--out", default="out/corpus_bokeh")
    parser.add_argument("--min-coc", type=float, default=10.0, help="px: smaller bokeh are skipped")
    args = parser.parse_args()
    rows = {}
    for scene_dir in args.scenes:
        name = os.path.basename(os.path.normpath(scene_dir))
        meta = json.load(open(os.path.join(scene_dir, "scene.json")))
        lens = meta["lens"]
        blades = int(lens.get("blades", 6))
        colour = read(scene_dir, meta["color"]).astype(np.float32)[..., ::-1]  # RGB
        truth = read(scene_dir, meta["truth"]).astype(np.float32)[..., ::-1]
        depth = read(scene_dir, meta["depth"])
        depth = depth[..., 0] if depth.ndim == 3 else depth
        depth_m = depth.astype(np.float32) / (meta.get("depthUnitsPerMetre", 1000) if depth.dtype == np.uint16 else 1)
        out = os.path.join(args.out, name)
        os.makedirs(out, exist_ok=True)
        tiles = []
        for x, y, d, coc in lights(colour, depth_m, lens):
            if abs(coc) < args.min_coc:
                continue
            half = int(math.ceil(0.75 * abs(coc))) + 2
            piece = crop(truth, x, y, half)
            if piece is None:
                continue
            luma = piece @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
            found, mask = measure(luma, blades)
            where = "near" if coc < 0 else "far"
            label = f"{where}-{d:.1f}m-x{x:.0f}y{y:.0f}"
            # Left: the truth, smoothed a little (its noise) and exposed so that the bokeh's
            # plateau is just below white: its shape, not its glare. Right: the silhouette measured.
            smooth = cv2.GaussianBlur(piece, (0, 0), 0.7)
            plateau = float(np.percentile(smooth @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32), 90))
            seen = (srgb(smooth / max(plateau, 1e-6)) * 255).astype(np.uint8)[..., ::-1]
            outline = np.repeat(mask[..., None], 3, axis=2).astype(np.uint8) * 255
            pair = [cv2.resize(t, (ZOOM_TO, ZOOM_TO), interpolation=cv2.INTER_NEAREST) for t in (seen, outline)]
            tile = np.hstack([pair[0], np.full((ZOOM_TO, 4, 3), 128, np.uint8), pair[1]])
            cv2.imwrite(os.path.join(out, f"{label}.png"), tile)
            tiles.append(tile)
            base = os.path.basename(os.path.normpath(os.path.dirname(os.path.join(scene_dir, meta["color"]))))
            rows.setdefault((base, label), []).append((name, tiles[-1]))
            print(json.dumps({"scene": name, "light": label, "cocPx": round(coc, 1), "blades": blades,
                              "rotationDeg": lens.get("bladeRotationDeg", 0.0),
                              "ratio": lens.get("apertureRatio", 1.0), **found}))
        if tiles:
            cv2.imwrite(os.path.join(out, "sheet.png"), np.vstack(tiles))
    for (base, label), row in rows.items():
        if len(row) > 1:
            gap = np.full((18 + ZOOM_TO, 8, 3), 64, np.uint8)
            sheet = np.hstack([np.hstack([np.vstack([np.zeros((18, t.shape[1], 3), np.uint8), t]), gap]) for _, t in row])
            step = row[0][1].shape[1] + 8
            for i, (name, _) in enumerate(row):
                cv2.putText(sheet, name.replace(base, "").lstrip("-") or "base (6 blades)", (i * step + 3, 13),
                            cv2.FONT_HERSHEY_SIMPLEX, 0.4, (255, 255, 255), 1)
            cv2.imwrite(os.path.join(args.out, f"{base}-{label}.png"), sheet)


if __name__ == "__main__":
    main()
