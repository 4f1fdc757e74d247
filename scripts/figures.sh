#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Regenerates the figures README.md and docs/ quote, each from the command that measures it, into
# docs/figures.json (machine-readable) and docs/figures.md (the same, to read), with the date, the
# commit and the machine of the run. The documents quote docs/figures.md.
#   scripts/figures.sh                 # every section, ~15 min on an idle 2-core machine
#   scripts/figures.sh tests timing    # only these sections; the others keep their last run
#   scripts/figures.sh --list          # the sections and their commands
# Run it from a clean checkout, built (scripts/setup.sh), on an otherwise idle machine: the
# timings are wall clock. Each section records its own date, commit and load average, so a partial
# run never passes for a full one. Exit: 0 when every section ran and exited 0, 1 otherwise, 2 on
# a bad argument. Needs jq (scripts/setup.sh installs it).
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
build=${DEFOCUS_BUILD:-build}
json=docs/figures.json
md=docs/figures.md
out=out/figures
export OPENCV_IO_ENABLE_OPENEXR=1

# name|what it gives|command (run from the repository root)
sections=(
  "tests|the number of tests, by CTest label, and of hard cases|for label in unit gl; do echo \"\$label tests: \$(ctest --test-dir $build -N -L \$label | sed -n 's/^Total Tests: //p')\"; done; echo \"all tests: \$(ctest --test-dir $build -N | sed -n 's/^Total Tests: //p')\"; echo \"hard cases: \$($build/tests/HardCasesGLTest --gtest_list_tests | sed -n 's|^  [^/]*/\\([^ ]*\\)_[a-z]* .*|\\1|p' | sort -u | wc -l), each a test per kernel or preset: \$($build/tests/HardCasesGLTest --gtest_list_tests | grep -c '^  .*/')\""
  "accuracy-tests|balanced, high and McIntosh's chain against the Cycles truth (tests/AccuracyGLTest)|$build/tests/AccuracyGLTest | grep -F '[ FIGURE'"
  "hard-cases|the hard cases' worst figures per setting (docs/stability.md)|$build/tests/HardCasesGLTest | grep -F '[ hard cases ]'"
  "sprites|bokeh sprites' plateau (tests/HighlightSpritesGLTest)|$build/tests/HighlightSpritesGLTest | grep -F '[ FIGURE'"
  "synthetic-tests|the synthetic truth's bokeh against the filter's CoC (docs/synthetic.md)|$build/tests/SyntheticSceneGLTest | grep -F '[ FIGURE'"
  "speed|ms per pass and per frame, 640x480 and 1920x1080, the balanced preset (README Speed)|$build/defocus-bench --json $out/bench.json"
  "plan|the per-frame plan against every pass on every pixel (README Speed)|$build/defocus-bench plan"
  "timing|each preset's frame time over the calibration pass (tests/timing_baseline.json)|$build/defocus-bench timing --runs 15"
  "accuracy|the accuracy sweep on the Blender scene (docs/accuracy.md, README Accuracy)|$build/defocus-bench-accuracy --runs 7 -o $out/accuracy"
  "synthetic|one frame of the synthetic thin-lens truth (README Synthetic truth)|$build/defocus-synthetic --scene spheres --focal-length 85 --f-number 1.4 --focus 5 -y -o $out/synthetic"
  "soak|10,000 frames: memory and GL objects (README Stability)|$build/defocus-soak --frames 10000"
  "gst-gl|the defocus element's frames per second in system and in GL memory, 640x480, no display (docs/gstreamer.md)|env -u DISPLAY -u WAYLAND_DISPLAY scripts/gst-gl-fps.sh $build 200"
  "gst-gl-1080|the same at 1920x1080 (docs/gstreamer.md)|env -u DISPLAY -u WAYLAND_DISPLAY scripts/gst-gl-fps.sh $build 30 1920x1080"
  "apertures-accuracy|the presets against the truths through other apertures (docs/accuracy.md Apertures; anchors from scripts/corpus/anchors.py --out out/corpus_anchors data/corpus-apertures, where present)|$build/defocus-bench-accuracy --scene data/corpus-apertures --anchors out/corpus_anchors --output $out/accuracy-apertures"
  "apertures-cost|ms per frame of the circle, 9 blades, a turned 7 and an oval beside the hexagon's, 640x480 and 1920x1080 (docs/accuracy.md Apertures)|scripts/aperture-cost.sh $build data/corpus/spheres-far-focus 640x480 20 3 && scripts/aperture-cost.sh $build data/corpus/spheres-far-focus 1920x1080 10 3"
)

field() { cut -d'|' -f"$2" <<<"$1"; }
wanted=()
for arg in "$@"; do
  case "$arg" in
    --list)
      for s in "${sections[@]}"; do printf '%-16s %s\n    %s\n' "$(field "$s" 1)" "$(field "$s" 2)" "$(field "$s" 3-)"; done
      exit 0 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *)
      found=0
      for s in "${sections[@]}"; do [ "$(field "$s" 1)" = "$arg" ] && found=1; done
      [ $found = 1 ] || { echo "figures.sh: no section '$arg' (see --list)" >&2; exit 2; }
      wanted+=("$arg") ;;
  esac
done
command -v jq >/dev/null || { echo "figures.sh: needs jq (scripts/setup.sh installs it)" >&2; exit 1; }
[ -x "$build/defocus" ] || { echo "figures.sh: no $build/defocus: build first (scripts/setup.sh)" >&2; exit 1; }
mkdir -p "$out"
[ -s "$json" ] || echo '{"sections": {}}' >"$json"

commit=$(git rev-parse --short HEAD)
git diff --quiet HEAD -- . ':!docs/figures.json' ':!docs/figures.md' || commit="$commit+changes"
renderer=$("$build/defocus" --info 2>/dev/null | sed -n 's/^GL renderer: *//p')
machine="$(nproc) cores, $(sed -n 's/^model name\s*: //p' /proc/cpuinfo | head -n 1), $renderer"
status=0
for s in "${sections[@]}"; do
  name=$(field "$s" 1)
  if ((${#wanted[@]})) && [[ ! " ${wanted[*]} " =~ " $name " ]]; then continue; fi
  command=$(field "$s" 3-)
  load=$(cut -d' ' -f1-3 /proc/loadavg)
  echo "figures.sh: $name: $command"
  start=$(date +%s.%N)
  bash -c "$command" >"$out/$name.txt" 2>"$out/$name.stderr"
  code=$?
  seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
  [ $code = 0 ] || { status=1; echo "figures.sh: $name exited $code (see $out/$name.stderr)" >&2; }
  tail -n 200 "$out/$name.txt" | sed 's/\r/\n/g' | grep -v '^frame [0-9]*/' >"$out/$name.kept"
  jq --arg name "$name" --arg what "$(field "$s" 2)" --arg command "$command" --arg date "$(date -u +%FT%TZ)" \
    --arg commit "$commit" --arg machine "$machine" --arg load "$load" --argjson seconds "$seconds" \
    --argjson exit "$code" --rawfile output "$out/$name.kept" \
    '.sections[$name] = {what: $what, command: $command, date: $date, commit: $commit, machine: $machine,
                         load_average_before: $load, seconds: $seconds, exit: $exit, output: $output}' \
    "$json" >"$json.new" && mv "$json.new" "$json"
done

# docs/figures.md from docs/figures.json, in the order of the sections above.
{
  echo "<!-- Generated by scripts/figures.sh from docs/figures.json: do not edit; run the script. -->"
  echo "# Figures"
  echo
  echo "Every figure README.md and docs/ quote comes from one of the commands below; this file holds"
  echo "their output as the last run of \`scripts/figures.sh\` left it. Each section says when, at which"
  echo "commit (\`+changes\`: with uncommitted changes) and on which machine it ran; timings are wall"
  echo "clock and hold only for that machine and its load (the load average before the section)."
  for s in "${sections[@]}"; do
    name=$(field "$s" 1)
    jq -e --arg n "$name" '.sections[$n]' "$json" >/dev/null || { printf '\n## %s\n\nNot run yet: `scripts/figures.sh %s`.\n' "$name" "$name"; continue; }
    jq -r --arg n "$name" '.sections[$n] |
      "\n## \($n): \(.what)\n\n```sh\n\(.command)\n```\n\n\(.date), commit \(.commit), \(.machine); load average \(.load_average_before) before; \(.seconds) s, exit \(.exit).\n\n```text\n\(.output)```"' "$json"
  done
} >"$md"
echo "figures.sh: wrote $json and $md"
exit $status
