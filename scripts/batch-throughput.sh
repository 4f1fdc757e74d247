#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Clips per minute through `defocus --batch` on this machine, three ways over the same manifest of
# CLIPS small clips (FRAMES frames each of the bundled TUM clip, 640x480, --quality fast):
#   per-core   one process per core, each a shard (scripts/batch-parallel.sh, GNU parallel)
#   in-flight  one process, two clips in flight (--in-flight 2: two workers, a GL context each)
#   serial     one process, one clip at a time
# The ways take turns, ROUNDS times (default 3), and the median of each is printed with the load
# average before and after: other work on the machine slows every way, so compare the ways within
# one run only.
#   scripts/batch-throughput.sh build/defocus [CLIPS=12] [FRAMES=4]       ROUNDS=5 ...
set -eu
defocus=$(realpath "${1:?usage: batch-throughput.sh DEFOCUS_BINARY [CLIPS] [FRAMES]}")
clips=${2:-12}
frames=${3:-4}
root=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d /tmp/defocus-throughput.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
for k in $(seq 0 $((clips - 1))); do
  printf '%s\t-\tout/clip%s/\t--frames %s --focus 1.0 --quality fast\n' "$root/data/tum_fr1_rpy" "$k" "$frames"
done > "$tmp/clips.tsv"
cd "$tmp"
echo "batch-throughput: $clips clips x $frames frames, $(nproc) cores, $(date -u +%FT%TZ)," \
  "commit $(git -C "$root" describe --always --dirty 2>/dev/null || echo unknown)"
echo "batch-throughput: load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
rounds=${ROUNDS:-3}
measure() { # NAME COMMAND... ; appends the wall time to NAME.times
  local name=$1; shift
  rm -rf out
  local start end done
  start=$(date +%s.%N)
  "$@" > "$name.log" 2>&1 || { echo "batch-throughput: $name failed:"; tail -n 20 "$name.log"; exit 1; }
  end=$(date +%s.%N)
  done=$(ls out/*.report.json | wc -l)
  [ "$done" -eq "$clips" ] || { echo "batch-throughput: $name did $done of $clips clips"; exit 1; }
  awk -v s="$start" -v e="$end" 'BEGIN { printf "%.3f\n", e - s }' >> "$name.times"
}
for _ in $(seq "$rounds"); do
  measure per-core env DEFOCUS="$defocus" JOBS="$(nproc)" "$root/scripts/batch-parallel.sh" clips.tsv -q
  measure in-flight "$defocus" --batch clips.tsv --in-flight 2 -q
  measure serial "$defocus" --batch clips.tsv -q
done
for name in per-core in-flight serial; do
  sort -n "$name.times" | awk -v n="$name" -v c="$clips" '{ t[NR] = $1 } END {
    m = t[int((NR + 1) / 2)]
    printf "batch-throughput: %-9s median %6.1f s  %6.1f clips/min  (runs:", n, m, c * 60 / m
    for (i = 1; i <= NR; i++) printf " %.1f", t[i]
    printf " s)\n" }'
done
echo "batch-throughput: load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
