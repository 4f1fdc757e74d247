#!/usr/bin/env bash
# The README's second command (and CI's): installs missing Debian packages, builds, runs every
# test under CTest (labels: unit = no GL needed, gl = renders on EGL, llvmpipe is enough).
#   scripts/test.sh            exit status is ctest's
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh" "$root/build"

exec ctest --test-dir "$root/build" --output-on-failure -j2
