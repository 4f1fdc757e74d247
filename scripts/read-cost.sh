#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# What reading a recorded clip costs on each number of reading threads: the bundled clip's colour
# and depth pairs, FRAMES of them (over and over), resized to SIZE as PNG files; then
# `defocus-bench read` on them (reading alone, each number of THREADS timed three times,
# interleaved) and the command line's wall time over them, depth of field and an H.264 output
# included, with one reading thread and with its default. Needs python3-opencv to make the frames.
#   scripts/read-cost.sh BIN_DIR [SIZE=1920x1080] [FRAMES=24] [THREADS=1,2]
# BIN_DIR holds defocus and defocus-bench (a build folder, or a GPU bundle's bin/).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$1
size=${2:-1920x1080}
frames=${3:-24}
threads=${4:-1,2}
width=${size%x*} height=${size#*x}
[[ $width =~ ^[0-9]+$ && $height =~ ^[0-9]+$ ]] || { echo "read-cost: error: SIZE '$size' is not WxH" >&2; exit 2; }
work=$(mktemp -d "${TMPDIR:-/tmp}/read-cost.XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/colour" "$work/depth"
# Python with the system's libraries (a GPU bundle's LD_LIBRARY_PATH would come first).
env -u LD_LIBRARY_PATH /usr/bin/python3 - "$root/data/tum_fr1_rpy" "$work" "$width" "$height" "$frames" <<'PY'
import glob, os, sys
import cv2
clip, work, width, height, frames = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
rgb = sorted(glob.glob(os.path.join(clip, "rgb", "*.png")))
depth = sorted(glob.glob(os.path.join(clip, "depth", "*.png")))
for k in range(frames):
    cv2.imwrite(os.path.join(work, "colour", f"{k:04d}.png"), cv2.resize(cv2.imread(rgb[k % len(rgb)]), (width, height)))
    cv2.imwrite(os.path.join(work, "depth", f"{k:04d}.png"),
                cv2.resize(cv2.imread(depth[k % len(depth)], cv2.IMREAD_UNCHANGED), (width, height),
                           interpolation=cv2.INTER_NEAREST))
PY
echo "read-cost: $frames frames of the bundled clip at $size; $(date -u +%FT%TZ)"
"$bin/defocus-bench" read "$work/colour" --depth "$work/depth" --depth-scale 5000 --threads "$threads" --passes 3
for t in 1 0; do
  start=$(date +%s.%N)
  "$bin/defocus" "$work/colour" --depth "$work/depth" --depth-scale 5000 --focus 1.0 --f-number 1.4 -q -y \
    --read-threads "$t" -o "$work/out.mp4" >"$work/cli.txt" 2>&1 || { cat "$work/cli.txt" >&2; exit 1; }
  end=$(date +%s.%N)
  echo "defocus --read-threads $t ($([[ $t == 0 ]] && echo default || echo one)): $(awk -v s="$start" -v e="$end" -v n="$frames" \
    'BEGIN { printf "%.1f ms per frame, wall, start-up included", 1000 * (e - s) / n }'); $(tail -n 1 "$work/cli.txt")"
done
