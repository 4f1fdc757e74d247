#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Builds the libFuzzer targets (clang, ASan + UBSan) and runs each over its committed corpus in
# fuzz/corpus/ for a few seconds: a crash, a leak, a sanitizer report or a failed invariant fails
# the script. Long runs and what they found: docs/fuzzing.md.
#   scripts/fuzz-smoke.sh [BUILD_DIR] [SECONDS_PER_TARGET]   (defaults: build-fuzz, 12; 4 targets)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath -m "${1:-"$root/build-fuzz"}")   # absolute: the targets run from a scratch folder
seconds=${2:-12}
targets=(fuzz_lists fuzz_depth_decode fuzz_color_decode fuzz_params)

# Clang and its runtime libraries (libFuzzer, ASan, UBSan) come from Debian; only what is missing
# is installed, as in scripts/setup.sh.
packages=(clang-14 libclang-rt-14-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "fuzz-smoke: installing ${missing[*]}"
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -q
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
  -DDEFOCUS_FUZZ=ON -DDEFOCUS_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" --target fuzzers -j "$(nproc)"

# New inputs go to a scratch copy of the corpus, so that the committed one only changes by hand
# (a -merge=1 run, see docs/fuzzing.md).
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
status=0
for target in "${targets[@]}"; do
  mkdir -p "$scratch/$target" "$scratch/artifacts"
  cp -r "$root/fuzz/corpus/$target/." "$scratch/$target/"
  echo "fuzz-smoke: $target for ${seconds} s over $(ls "$scratch/$target" | wc -l) corpus files"
  if ! (cd "$scratch" && "$build/fuzz/$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
        -print_final_stats=1 -artifact_prefix="$scratch/artifacts/$target-" "$scratch/$target" \
        >"$scratch/$target.log" 2>&1); then
    echo "fuzz-smoke: $target FAILED; its log ends:"
    tail -n 40 "$scratch/$target.log"
    for artifact in "$scratch/artifacts/$target-"*; do
      [ -e "$artifact" ] || continue
      mkdir -p "$build/fuzz-artifacts"
      cp "$artifact" "$build/fuzz-artifacts/"
      echo "fuzz-smoke: reproducer kept as $build/fuzz-artifacts/$(basename "$artifact")"
    done
    status=1
  else
    grep -E "^stat::number_of_executed_units" "$scratch/$target.log" | sed "s/^/fuzz-smoke: $target /"
  fi
done
exit $status
