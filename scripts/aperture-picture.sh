#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# The picture of README's apertures: one corpus scene (its lens, max-coc its largest CoC) through
# the hexagon, the circle, 9 blades and a 2:1 anamorphic oval with `defocus`, side by side and
# labelled (the top five eighths of each frame: the lights and the spheres), as sRGB PNG. Needs
# python3-opencv.
#   scripts/aperture-picture.sh BUILD_DIR [OUT=docs/images/apertures.png] [SCENE=data/corpus/spheres-far-focus]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$1
out=${2:-$root/docs/images/apertures.png}
scene=${3:-$root/data/corpus/spheres-far-focus}
[[ -f $scene/scene.json ]] || { echo "aperture-picture: error: $scene/scene.json: no such file" >&2; exit 1; }
work=$(mktemp -d "${TMPDIR:-/tmp}/aperture-picture.XXXXXX")
trap 'rm -rf "$work"' EXIT
read -r lens color depth < <(/usr/bin/python3 - "$scene/scene.json" <<'PY'
import json, sys
meta = json.load(open(sys.argv[1]))
l = meta["lens"]
options = (f"--focal-length={l['focalLengthMm']},--f-number={l['fNumber']},--focus={l['focusM']},"
           f"--sensor-width={l['sensorWidthMm']},--fov-from=focal-length,--max-coc=64")
print(options, meta["color"], meta["depth"])
PY
)
lens=${lens//,/ }
names=("hexagon (6 blades)" "circle (--blades 0)" "9 blades" "oval (--blades 0 --aperture-ratio 2)")
options=("--blades 6" "--blades 0" "--blades 9" "--blades 0 --aperture-ratio 2")
for i in "${!names[@]}"; do
  # shellcheck disable=SC2086 # $lens and the options are lists of options
  "$build/defocus" "$scene/$color" --depth "$scene/$depth" --depth-scale 1000 $lens ${options[$i]} -q -y -o "$work/$i.png" 2>/dev/null
done
/usr/bin/python3 - "$work" "$out" "${names[@]}" <<'PY'
import sys
import cv2, numpy as np
work, out, names = sys.argv[1], sys.argv[2], sys.argv[3:]
tiles = []
for i, name in enumerate(names):
    image = cv2.imread(f"{work}/{i}.png")[: 5 * 480 // 8]  # the lights and the spheres
    cv2.rectangle(image, (0, 0), (image.shape[1], 28), (0, 0, 0), cv2.FILLED)
    cv2.putText(image, name, (8, 20), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 255, 255), 1, cv2.LINE_AA)
    tiles.append(image)
cv2.imwrite(out, np.vstack([np.hstack(tiles[:2]), np.hstack(tiles[2:])]))
print(f"aperture-picture: wrote {out}")
PY
