#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
# The method table of docs/accuracy.md ("The table") from a run of defocus-bench-accuracy on the
# Blender scene: its accuracy.csv, the 32F rows (every 16F row is in the CSV), the presets in
# bold, the unblurred input's dB given on the command line (the run prints it; the CSV has no row).
#   scripts/accuracy-table.py out/accuracy/accuracy.csv 16.47
import csv
import sys

PRESETS = {("rhombi-near", "4", "half"): "fast", ("rhombi-near", "6", "half"): "balanced",
           ("rhombi-near", "12", "full"): "high"}


def number(text, digits):
    try:
        return f"{float(text):.{digits}f}"
    except ValueError:
        return ""


if len(sys.argv) != 3:
    sys.exit("usage: scripts/accuracy-table.py ACCURACY_CSV INPUT_DB")
print("| method | samples | scale | targets | linear dB | sRGB dB | SSIM | in-focus dB | out-of-focus dB "
      "| depth-edge dB | wall ms | GPU ms | front |")
print("|---|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|:-:|")
print(f"| input (unblurred) | | | | {float(sys.argv[2]):.2f} | | | | | | | | |")
for row in csv.DictReader(open(sys.argv[1])):
    reference = row["method"].startswith("reference")
    if row["precision"] != "32F" and not reference:
        continue
    name = row["method"]
    preset = PRESETS.get((row["method"], row["samples"], row["resolution"]))
    if preset:
        name = f"**{name} ({preset})**"
    if reference:
        name += f" (CPU, {row['runs']} run{'s' if row['runs'] != '1' else ''})"
    cells = [name, "" if reference else row["samples"], "" if reference else row["resolution"],
             "" if reference else row["precision"], number(row["psnr_linear_db"], 2),
             number(row["psnr_srgb_db"], 2), number(row["ssim"], 3), number(row["psnr_in_focus_db"], 2),
             number(row["psnr_out_of_focus_db"], 2), number(row["psnr_depth_edge_db"], 2),
             number(row["wall_ms_median"], 0 if reference else 1), number(row["gpu_ms_median"], 1),
             "●" if row["pareto"] == "1" else ""]
    print("| " + " | ".join(cells) + " |")
