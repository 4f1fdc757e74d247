#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Builds defocus as the subproject of tests/subproject (add_subdirectory, as FetchContent does):
# the parent's build type is left alone, no test of defocus is defined, and the parent's program
# linked to defocus::defocus gives the CLI's PNG, byte for byte.
#   tests/subproject-test.sh DEFOCUS_CLI [COMPILER_LAUNCHER]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cli=$1 launcher=${2:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "subproject-test: $*"; exit 1; }

cmake -S "$root/tests/subproject" -B "$work/build" -G Ninja -DDEFOCUS_SOURCE_DIR="$root" \
  ${launcher:+-DCMAKE_CXX_COMPILER_LAUNCHER=$launcher} >/dev/null
# The parent has no build type: defocus must not pick one (Release's -O3) for its own targets.
grep -q "^CMAKE_BUILD_TYPE:STRING=$" "$work/build/CMakeCache.txt" || fail "defocus set the parent's build type"
! grep -q -- "-O3" "$work/build/build.ninja" || fail "defocus compiles with a build type of its own in a parent that has none"
targets=$(cmake --build "$work/build" --target help)
! grep -qE "SettingsTest|GstDefocusGLTest" <<<"$targets" || fail "defocus defined its tests in a parent project"
cmake --build "$work/build" --target parent-consumer >/dev/null

read -r _ rgb _ depth < <(sed -n 9p "$root/data/tum_fr1_rpy/associations.txt")
color=$root/data/tum_fr1_rpy/$rgb depth=$root/data/tum_fr1_rpy/$depth
"$work/build/parent-consumer" "$color" "$depth" 5000 1.0 1.4 balanced "$work/parent.png" >/dev/null
"$cli" "$color" --depth "$depth" --depth-scale 5000 --focus 1.0 --f-number 1.4 -o "$work/cli.png" -q >/dev/null
cmp -s "$work/parent.png" "$work/cli.png" || fail "the parent's program differs from the CLI"
echo "subproject-test: defocus as a subproject: build type left alone, no tests, output = CLI byte for byte"
