#!/bin/sh
# SPDX-License-Identifier: LGPL-2.1-or-later
# Renders the accuracy corpus with Blender (Debian 12: apt-get install blender) and assembles
# each scene folder: scripts/corpus/scenes.py renders the pinhole input and SEEDS thin-lens
# renders of SAMPLES samples each, scripts/corpus/assemble.py averages them into the truth and
# states how converged it is (scene.json). Raw renders go to out/corpus_render/, scene folders to
# data/corpus/ (or $CORPUS_OUT). Runs niced; a scene already assembled is skipped.
# A name BASE--APERTURE (scenes.py) is BASE through another aperture: only its truths are
# rendered, with BASE's sampling (its scene.json) unless SAMPLES or ADAPTIVE say otherwise, and
# its folder goes to data/corpus-apertures/ (or $CORPUS_OUT), holding only the truth and a
# scene.json that names BASE's colour and depth in data/corpus/ (or $CORPUS_BASES; it must be
# there).
#   scripts/corpus/render.sh                       # every scene
#   SAMPLES=256 scripts/corpus/render.sh portrait-50 railing-lights
#   scripts/corpus/render.sh --variants            # every variant of data/corpus-apertures/
#   scripts/corpus/render.sh spheres-far-focus--circle spheres-far-focus--7blades-rot15
# scenes.py's aperture-probe (point lights on black, to see which way an aperture points) is
# rendered, with its variants, outside the corpus:
#   CORPUS_OUT=out/corpus_probe CORPUS_BASES=out/corpus_probe SAMPLES=256 ADAPTIVE= \
#       scripts/corpus/render.sh aperture-probe aperture-probe--5blades aperture-probe--circle-ratio2
set -eu
cd "$(dirname "$0")/../.."
# SAMPLES, ADAPTIVE: unset = 384 and "0.01 24" for a scene, its base's for a variant.
SAMPLES_SET=${SAMPLES+1} ADAPTIVE_SET=${ADAPTIVE+1}
SAMPLES=${SAMPLES:-384}          # thin-lens samples per seed, at most (adaptive sampling)
ADAPTIVE=${ADAPTIVE-"0.01 24"}   # noise threshold and minimum samples; "" = every pixel SAMPLES
SEEDS=${SEEDS:-2}                # independent truth renders (>= 2: their agreement is the noise)
PINHOLE_SAMPLES=${PINHOLE_SAMPLES:-32}
RAW=out/corpus_render
command -v blender >/dev/null || { echo "render.sh: blender not found (apt-get install blender)" >&2; exit 1; }
BLENDER="nice -n 19 blender -b --factory-startup --python scripts/corpus/scenes.py --"
if [ $# -eq 0 ]; then
    set -- $($BLENDER --list 2>/dev/null | grep -E '^[a-z0-9-]+$')
elif [ "$1" = --variants ]; then
    set -- $($BLENDER --list-variants 2>/dev/null | grep -E '^[a-z0-9-]+--[a-z0-9.-]+$')
fi
scene_samples=$SAMPLES scene_adaptive=$ADAPTIVE
for scene in "$@"; do
    base=${scene%%--*}
    SAMPLES=$scene_samples ADAPTIVE=$scene_adaptive
    if [ "$base" = "$scene" ]; then
        OUT=${CORPUS_OUT:-data/corpus}
    else
        OUT=${CORPUS_OUT:-data/corpus-apertures}
        base_dir=${CORPUS_BASES:-data/corpus}/$base
        [ -f "$base_dir/scene.json" ] ||
            { echo "render.sh: $scene: its base $base_dir is not there (render $base first)" >&2; exit 1; }
        # The base's sampling, where not given: the same truth quality, the same noise.
        [ -n "$SAMPLES_SET" ] || SAMPLES=$(/usr/bin/python3 -c \
            'import json,sys; print(json.load(open(sys.argv[1]))["render"]["truthSamplesPerSeed"])' "$base_dir/scene.json")
        [ -n "$ADAPTIVE_SET" ] || ADAPTIVE=$(/usr/bin/python3 -c \
            'import json,sys; print(json.load(open(sys.argv[1]))["render"]["truthAdaptive"])' "$base_dir/scene.json")
    fi
    if [ -f "$OUT/$scene/scene.json" ]; then
        echo "render.sh: $scene: already in $OUT, skipped"
        continue
    fi
    raw="$RAW/$scene"
    mkdir -p "$raw"
    start=$(date +%s)
    [ "$base" != "$scene" ] || { [ -f "$raw/color_linear.exr" ] && [ -f "$raw/lens.json" ]; } ||
        $BLENDER --scene "$scene" --pass pinhole --samples "$PINHOLE_SAMPLES" --out "$raw" >"$raw/pinhole.log" 2>&1
    seed=1
    while [ "$seed" -le "$SEEDS" ]; do
        if [ ! -f "$raw/truth_seed$seed.exr" ]; then
            seed_start=$(date +%s)
            $BLENDER --scene "$scene" --pass truth --samples "$SAMPLES" --seed "$seed" --out "$raw" \
                ${ADAPTIVE:+--adaptive $ADAPTIVE} \
                >"$raw/truth_seed$seed.log" 2>&1 ||
                { echo "render.sh: $scene: truth render failed ($raw/truth_seed$seed.log):" >&2
                  tail -n 1 "$raw/truth_seed$seed.log" >&2; exit 1; }
            echo $(($(date +%s) - seed_start)) >"$raw/truth_seed$seed.seconds"  # niced, wall clock
        fi
        seed=$((seed + 1))
    done
    printf '{"pinholeSamples": %s, "truthSamplesPerSeed": %s, "truthAdaptive": "%s"}\n' \
        "$PINHOLE_SAMPLES" "$SAMPLES" "$ADAPTIVE" >"$raw/render.json"
    if [ "$base" = "$scene" ]; then
        /usr/bin/python3 scripts/corpus/assemble.py "$raw" "$OUT/$scene"
    else
        /usr/bin/python3 scripts/corpus/assemble.py "$raw" "$OUT/$scene" --base "$base_dir"
    fi
    echo "render.sh: $scene: $(($(date +%s) - start)) s"
done
