#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Installs the Debian packages defocus needs, only those that are missing, then configures and
# builds it. Safe to run again: a second run installs nothing and rebuilds only what changed.
#   scripts/setup.sh [--tests | --all] [BUILD_DIR]   (default: build)
#     (no option)  what building defocus and scripts/demo.sh need
#     --tests      and what the default test tier needs (scripts/test.sh): GStreamer's tools and
#                  plugins for the element's tests (its GL library's elements, and Xvfb for its
#                  GL memory under an X display), GNU parallel for the batch test
#     --all        and what every tier needs (scripts/test.sh --all): Slurm and munge for the
#                  one-node cluster test, and the plugins of the README's GStreamer pipelines.
#                  The VM and container tests install their own (qemu, podman).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
tier=build
case ${1:-} in
  --tests) tier=tests; shift ;;
  --all) tier=all; shift ;;
  -*) echo "setup.sh: unknown option $1 (use --tests or --all)" >&2; exit 2 ;;
esac
build=${1:-"$root/build"}

# Why each package is here: README.md, section "Dependencies".
packages=(
  build-essential cmake ninja-build pkg-config
  libopencv-dev            # image/video decode + encode, highgui display, colour maps
  libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri   # headless EGL + OpenGL 4.5 (llvmpipe without a GPU)
  libepoxy-dev             # GL/EGL function loading
  libglm-dev               # vector maths for sample offsets
  libv4l-dev               # V4L2 camera headers
  libcli11-dev             # command-line parsing
  libfmt-dev libspdlog-dev # formatting and logging
  nlohmann-json3-dev       # JSON timings and benchmark output
  jq                       # scripts/figures.sh: docs/figures.json
  libgtest-dev libgmock-dev googletest   # the test suite, configured with every build
  libgstreamer1.0-dev libgstreamer-plugins-base1.0-dev   # the GStreamer element (gst/)
)
if [ "$tier" != build ]; then
  packages+=(
    gstreamer1.0-tools gstreamer1.0-plugins-base gstreamer1.0-plugins-good   # the element's tests: gst-launch-1.0, pngdec, imagefreeze
    gstreamer1.0-gl xvfb   # the element's GL memory tests: glupload, gldownload; an X display for GLX
    parallel               # the batch test: defocus --batch under GNU parallel
  )
fi
if [ "$tier" = all ]; then
  packages+=(
    slurm-wlm munge        # the one-node Slurm test (slurmctld, slurmd, sbatch)
    gstreamer1.0-plugins-ugly gstreamer1.0-libav gstreamer1.0-x   # README pipelines: x264enc, H.264 decoding, ximagesink
  )
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -q
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$(nproc)"
