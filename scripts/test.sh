#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# The README's second command (and CI's, with --all): installs the Debian packages the tier needs
# when missing (scripts/setup.sh), builds, and runs a tier of the tests under CTest, chosen by label.
#   scripts/test.sh [--all] [CTEST_OPTIONS...]      exit status is ctest's
#
#   (default)  every test that needs no VM, container or cluster and is not a soak or one of the
#              long end-to-end runs below: the GoogleTest suites (labels unit = no GL, gl = renders
#              on EGL, llvmpipe is enough; gst = the GStreamer element's harness tests), and the
#              end-to-end tests labelled batch, corpus, display, and exit_status and
#              library_symbols, and gst_frame_count. About 2 minutes on 2 cores (README,
#              "Testing", gives the measured run).
#   --all      every tier; what .ci/run calls. It adds the tests with these labels:
#                long        the hard-case sweep (HardCasesGLTest) and gst-launch-1.0 pipelines
#                install     install into a prefix (programs, scripts, tests/consumer built against
#                            it, twice) and the .deb of cpack -G DEB
#                subproject  defocus under another project's add_subdirectory (compiles it again)
#                timing      the frame-timing comparator (runs alone: it measures)
#                soak        2,000 frames with memory and GL objects flat
#                slurm       a one-node Slurm cluster (root; slurm-wlm and munge, which --all installs)
#                v4l2        capture against kernel drivers in a qemu VM (installs qemu itself)
#                container   the Containerfile built with podman and run (installs podman itself; ~20 min)
#              The tests that cannot run here skip with code 77, which CTest reports as skipped.
# Other options go to ctest, e.g. `scripts/test.sh -R Lens` or `scripts/test.sh --all -L v4l2`.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# The labels the default tier leaves out (`ctest -LE`); a test with any of them is left out.
slow_labels='long|install|subproject|timing|soak|slurm|v4l2|container'

if [ "${1:-}" = --all ]; then
  shift
  "$root/scripts/setup.sh" --all "$root/build"
  exec ctest --test-dir "$root/build" --output-on-failure -j2 "$@"
fi
"$root/scripts/setup.sh" --tests "$root/build"
exec ctest --test-dir "$root/build" --output-on-failure -j2 -LE "$slow_labels" "$@"
