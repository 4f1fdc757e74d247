#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# libdefocus holds the product, not the benchmarks: no function or object that the benchmarks'
# library (bench/, defocus_bench_lib) defines is in libdefocus.so, and none of the method zoo's
# names is either (the registry, the metrics, the other methods' passes, the timing calibration),
# should its sources move back into filter/. Defect caught: a product source that includes a
# benchmark header, or a benchmark source listed in the product's library, which ships the zoo to
# every user of the library.
#   tests/library-symbols-test.sh LIBDEFOCUS_SO BENCH_LIB_A      (CTest: library_symbols, label unit)
set -euo pipefail
lib=$1 bench=$2
fail() { echo "library-symbols-test: $*"; exit 1; }
[ -f "$lib" ] || fail "$lib: no such file"
[ -f "$bench" ] || fail "$bench: no such file (build defocus_bench_lib)"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Everything libdefocus.so defines, local symbols included (its static parts' are made local).
nm -C --defined-only "$lib" | cut -d' ' -f3- | sort -u >"$work/lib"
# The check reads the library's own symbol table: a stripped library would pass without looking.
grep -q '^defocus::Pipeline::' "$work/lib" || fail "$lib has no symbol table to check (stripped?)"

# Functions and objects the benchmarks' library defines (not inline or template code, weak in both).
nm -C --defined-only "$bench" | awk '$2 ~ /^[TDBR]$/' | cut -d' ' -f3- | sort -u >"$work/bench"
[ -s "$work/bench" ] || fail "$bench defines nothing"
comm -12 "$work/lib" "$work/bench" >"$work/both"
if [ -s "$work/both" ]; then
  echo "library-symbols-test: libdefocus.so holds $(wc -l <"$work/both") symbols of the benchmarks' library:"
  head -20 "$work/both"
  exit 1
fi

zoo='defocus::(Method|MethodInfo|PipelineMethod|ReferenceMethod|Preset\b|presets\(|preset\(|createMethod|methodRegistry|findMethod|blenderSpheresLens)|ReferenceScatter|PoissonGather|LazyGather|GaussianBlurPass|CalibrationPass|Metrics|psnr|ssim|zoneMap'
if grep -E "$zoo" "$work/lib" >"$work/named"; then
  echo "library-symbols-test: libdefocus.so holds the benchmarks' code:"
  head -20 "$work/named"
  exit 1
fi
echo "library-symbols-test: libdefocus.so holds none of the $(wc -l <"$work/bench") symbols of the benchmarks' library"
