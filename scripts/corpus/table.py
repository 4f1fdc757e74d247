#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
# Markdown tables for docs/accuracy.md from a corpus run's corpus.json (defocus-bench accuracy
# --scene ... --anchors ...): linear PSNR per scene, min and median, and the share of the
# squared error per zone.   scripts/corpus/table.py out/accuracy/corpus.json
import json
import statistics
import sys

COLUMNS = ["input", "fast", "balanced", "high", "blender-defocus", "gegl-lens-blur"]
ZONES = ["lights", "depth-edges", "in-focus", "near", "far"]


def fmt(x):
    return "–" if x is None else f"{x:.2f}"


data = json.load(open(sys.argv[1]))
columns = [c for c in COLUMNS if any(r["what"] == c for s in data["scenes"] for r in s["results"])]
print("| scene | lens | truth dB | " + " | ".join(columns) + " |")
print("|---|---|---:|" + "---:|" * len(columns))
values = {c: [] for c in columns}
for s in data["scenes"]:
    lens = s["lens"]
    by = {r["what"]: r for r in s["results"]}
    cells = []
    for c in columns:
        v = by[c]["psnrLinearDb"] if c in by else None
        if v is not None:
            values[c].append(v)
        cells.append(fmt(v))
    print(f"| {s['scene']} | {lens['focalLengthMm']:g} mm f/{lens['fNumber']:g} at {lens['focusM']:g} m | "
          f"{fmt(s['truthEstimatedPsnrDb'])} | " + " | ".join(cells) + " |")
for name, f in [("**minimum**", min), ("**median**", statistics.median)]:
    print(f"| {name} | | | " + " | ".join(fmt(f(values[c])) if values[c] else "–" for c in columns) + " |")
print()
print("| scene | what | " + " | ".join(ZONES) + " |")
print("|---|---|" + "---:|" * len(ZONES))
for s in data["scenes"]:
    for r in s["results"]:
        if r["what"] == "input":
            cells = [f"{100 * r['zones'][z]['pixelShare']:.0f} % of pixels" for z in ZONES]
        elif r["what"] in ("balanced", "high", "blender-defocus"):
            cells = [f"{fmt(r['zones'][z]['psnrLinearDb'])} ({100 * r['zones'][z]['errorShare']:.0f} %)" for z in ZONES]
        else:
            continue
        print(f"| {s['scene']} | {r['what']} | " + " | ".join(cells) + " |")
