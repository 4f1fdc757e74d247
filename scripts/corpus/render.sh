#!/bin/sh
# SPDX-License-Identifier: LGPL-2.1-or-later
# Renders the accuracy corpus with Blender (Debian 12: apt-get install blender) and assembles
# each scene folder: scripts/corpus/scenes.py renders the pinhole input and SEEDS thin-lens
# renders of SAMPLES samples each, scripts/corpus/assemble.py averages them into the truth and
# states how converged it is (scene.json). Raw renders go to out/corpus_render/, scene folders to
# data/corpus/ (or $CORPUS_OUT). Runs niced; a scene already assembled is skipped.
#   scripts/corpus/render.sh                       # every scene
#   SAMPLES=256 scripts/corpus/render.sh portrait-50 railing-lights
set -eu
cd "$(dirname "$0")/../.."
SAMPLES=${SAMPLES:-384}          # thin-lens samples per seed, at most (adaptive sampling)
ADAPTIVE=${ADAPTIVE-"0.01 24"}   # noise threshold and minimum samples; "" = every pixel SAMPLES
SEEDS=${SEEDS:-2}                # independent truth renders (>= 2: their agreement is the noise)
PINHOLE_SAMPLES=${PINHOLE_SAMPLES:-32}
OUT=${CORPUS_OUT:-data/corpus}
RAW=out/corpus_render
command -v blender >/dev/null || { echo "render.sh: blender not found (apt-get install blender)" >&2; exit 1; }
BLENDER="nice -n 19 blender -b --factory-startup --python scripts/corpus/scenes.py --"
if [ $# -eq 0 ]; then
    set -- $($BLENDER --list 2>/dev/null | grep -E '^[a-z0-9-]+$')
fi
for scene in "$@"; do
    if [ -f "$OUT/$scene/scene.json" ]; then
        echo "render.sh: $scene: already in $OUT, skipped"
        continue
    fi
    raw="$RAW/$scene"
    mkdir -p "$raw"
    start=$(date +%s)
    [ -f "$raw/color_linear.exr" ] && [ -f "$raw/lens.json" ] ||
        $BLENDER --scene "$scene" --pass pinhole --samples "$PINHOLE_SAMPLES" --out "$raw" >"$raw/pinhole.log" 2>&1
    seed=1
    while [ "$seed" -le "$SEEDS" ]; do
        [ -f "$raw/truth_seed$seed.exr" ] ||
            $BLENDER --scene "$scene" --pass truth --samples "$SAMPLES" --seed "$seed" --out "$raw" \
                ${ADAPTIVE:+--adaptive $ADAPTIVE} \
                >"$raw/truth_seed$seed.log" 2>&1
        seed=$((seed + 1))
    done
    printf '{"pinholeSamples": %s, "truthSamplesPerSeed": %s, "truthAdaptive": "%s"}\n' \
        "$PINHOLE_SAMPLES" "$SAMPLES" "$ADAPTIVE" >"$raw/render.json"
    /usr/bin/python3 scripts/corpus/assemble.py "$raw" "$OUT/$scene"
    echo "render.sh: $scene: $(($(date +%s) - start)) s"
done
