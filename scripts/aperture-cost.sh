#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# What each aperture costs: `defocus` over FRAMES copies of one corpus scene's colour and depth
# (float EXR, its lights above white: the bokeh sprites run) at SIZE, with the scene's lens and
# max-coc scaled with the width, for each aperture in turn, ROUNDS rounds alternating; the median
# ms per frame of each (the CLI's own "ms/frame", which leaves out start-up), and its ratio to the
# hexagon's. Needs python3-opencv to make the frames.
#   scripts/aperture-cost.sh BUILD_DIR [SCENE=data/corpus/spheres-far-focus] [SIZE=640x480] [FRAMES=20] [ROUNDS=3]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$1
scene=${2:-$root/data/corpus/spheres-far-focus}
size=${3:-640x480}
frames=${4:-20}
rounds=${5:-3}
preset=${QUALITY:-balanced}
width=${size%x*} height=${size#*x}
[[ $width =~ ^[0-9]+$ && $height =~ ^[0-9]+$ ]] || { echo "aperture-cost: error: SIZE '$size' is not WxH" >&2; exit 2; }
[[ -f $scene/scene.json ]] || { echo "aperture-cost: error: $scene/scene.json: no such file" >&2; exit 1; }
work=$(mktemp -d "${TMPDIR:-/tmp}/aperture-cost.XXXXXX")
trap 'rm -rf "$work"' EXIT
# The frames, and the lens as defocus options (max-coc: the scene's largest CoC at 640 px, scaled).
# Python with the system's libraries: under scripts/gpu-figures.sh run, LD_LIBRARY_PATH puts the
# bundle's first, and numpy fails its start-up check against them.
lens=$(env -u LD_LIBRARY_PATH OPENCV_IO_ENABLE_OPENEXR=1 /usr/bin/python3 - "$scene" "$work" "$width" "$height" "$frames" <<'PY'
import json, os, sys
import cv2, numpy as np
scene, work, width, height, frames = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
meta = json.load(open(os.path.join(scene, "scene.json")))
color = cv2.imread(os.path.join(scene, meta["color"]), cv2.IMREAD_UNCHANGED)
depth = cv2.imread(os.path.join(scene, meta["depth"]), cv2.IMREAD_UNCHANGED)
if depth.dtype == np.uint16:
    depth = depth.astype(np.float32) / meta.get("depthUnitsPerMetre", 1000.0)
color = cv2.resize(color, (width, height), interpolation=cv2.INTER_AREA)
depth = cv2.resize(depth, (width, height), interpolation=cv2.INTER_NEAREST)
os.makedirs(os.path.join(work, "rgb")); os.makedirs(os.path.join(work, "depth"))
for i in range(frames):
    cv2.imwrite(os.path.join(work, "rgb", f"{i:04d}.exr"), color.astype(np.float32))
    cv2.imwrite(os.path.join(work, "depth", f"{i:04d}.exr"), depth.astype(np.float32))
lens = meta["lens"]
f, n, s = lens["focalLengthMm"] * 1e-3, lens["fNumber"], lens["focusM"]
z = depth[depth > 0]
coc = np.abs(f / n * f / s * (z - s) / z) * 640 / (lens["sensorWidthMm"] * 1e-3)
print(f"--focal-length {lens['focalLengthMm']} --f-number {n} --focus {s} --sensor-width {lens['sensorWidthMm']} "
      f"--fov-from focal-length --max-coc {min(512.0, float(np.ceil(coc.max())) * width / 640.0):g}")
PY
)
apertures=("hexagon:--blades 6" "circle:--blades 0" "9 blades:--blades 9" "7 blades at 15 deg:--blades 7 --blade-rotation 15"
           "oval, ratio 2:--blades 0 --aperture-ratio 2")
declare -A times
for round in $(seq "$rounds"); do
  for entry in "${apertures[@]}"; do
    name=${entry%%:*} options=${entry#*:}
    # shellcheck disable=SC2086 # $lens and $options are lists of options
    line=$("$build/defocus" "$work/rgb" --depth "$work/depth" $lens $options --quality "$preset" \
      -o "$work/out/" -y 2>&1 | grep -o '[0-9.]* ms/frame' | head -1) || true
    [[ -n $line ]] || { echo "aperture-cost: error: defocus failed for $name" >&2; exit 1; }
    times[$name]+="${line% ms/frame} "
  done
done
echo "# $(date -u +%FT%TZ), $(git -C "$root" rev-parse --short HEAD), $size, $frames frames x $rounds rounds, $preset, $(basename "$scene")"
echo "| aperture | ms per frame (median of $rounds) | vs the hexagon | each round |"
echo "|---|---:|---:|---|"
median() { tr ' ' '\n' | grep -v '^$' | sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
hexagon=$(echo "${times[hexagon]}" | median)
for entry in "${apertures[@]}"; do
  name=${entry%%:*}
  ms=$(echo "${times[$name]}" | median)
  printf '| %s | %.1f | %.2f | %s|\n' "$name" "$ms" "$(echo "$ms / $hexagon" | bc -l)" "${times[$name]}"
done
