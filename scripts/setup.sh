#!/usr/bin/env bash
# Installs the Debian packages defocus needs, only those that are missing, then configures and
# builds it. Safe to run again: a second run installs nothing and rebuilds only what changed.
#   scripts/setup.sh [BUILD_DIR]   (default: build)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
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
  libgtest-dev libgmock-dev googletest   # tests
  libbenchmark-dev         # micro-benchmarks
  libgstreamer1.0-dev libgstreamer-plugins-base1.0-dev   # the GStreamer element (gst/)
  gstreamer1.0-tools gstreamer1.0-plugins-base gstreamer1.0-plugins-good   # its tests: gst-launch-1.0, pngdec, imagefreeze
  gstreamer1.0-plugins-ugly gstreamer1.0-libav gstreamer1.0-x   # README pipelines: x264enc, H.264 decoding, ximagesink
  slurm-wlm munge parallel # many clips: the one-node Slurm test (slurmctld, slurmd, sbatch) and the GNU parallel test
)

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
