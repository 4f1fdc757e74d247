#!/usr/bin/env bash
# Clips per minute through `defocus --batch` on this machine, three ways over the same manifest of
# CLIPS small clips (FRAMES frames each of the bundled TUM clip, 640x480, --quality fast):
#   per-core   one process per core, each a shard (scripts/batch-parallel.sh, GNU parallel)
#   in-flight  one process, two clips in flight (--in-flight 2: two workers, a GL context each)
#   serial     one process, one clip at a time
# Prints one line per way and the load average before and after (other work on the machine
# slows every way; compare the ways within one run only).
#   scripts/batch-throughput.sh build/defocus [CLIPS=12] [FRAMES=4]
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
  "commit $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"
echo "batch-throughput: load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
measure() { # NAME COMMAND...
  local name=$1; shift
  rm -rf out
  local start end
  start=$(date +%s.%N)
  "$@" > "$name.log" 2>&1 || { echo "batch-throughput: $name failed:"; tail -n 20 "$name.log"; exit 1; }
  end=$(date +%s.%N)
  local done
  done=$(ls out/*.report.json | wc -l)
  [ "$done" -eq "$clips" ] || { echo "batch-throughput: $name did $done of $clips clips"; exit 1; }
  awk -v n="$name" -v c="$clips" -v s="$start" -v e="$end" \
    'BEGIN { printf "batch-throughput: %-9s %6.1f s  %6.1f clips/min\n", n, e - s, c * 60 / (e - s) }'
}
measure per-core env DEFOCUS="$defocus" JOBS="$(nproc)" "$root/scripts/batch-parallel.sh" clips.tsv -q
measure in-flight "$defocus" --batch clips.tsv --in-flight 2 -q
measure serial "$defocus" --batch clips.tsv -q
echo "batch-throughput: load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
