#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Builds the suite with AddressSanitizer and UndefinedBehaviorSanitizer and runs the tests that
# exercise the CPU code (label unit: sources, sinks, lens, settings, depth preparation, analysis,
# autofocus, metrics). Any report fails the run.
#   scripts/sanitize.sh [BUILD_DIR]   (default: build-asan)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-"$root/build-asan"}
"$root/scripts/setup.sh" "$root/build" >/dev/null
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer" >/dev/null
cmake --build "$build" -j "$(nproc)"
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir "$build" -L unit --output-on-failure -j "$(nproc)"
