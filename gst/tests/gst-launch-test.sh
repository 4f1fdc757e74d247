#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# The defocus element from the command line: gst-inspect-1.0 describes it cleanly, a gst-launch-1.0
# pipeline over the bundled clip gives the same frames as the defocus CLI (decoded pixels, byte for
# byte), and without OpenGL the pipeline fails with the element's message, not a crash.
#   gst/tests/gst-launch-test.sh BUILD_DIR DEFOCUS_CLI
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$1 cli=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export GST_PLUGIN_PATH=$build/gst GST_REGISTRY=$work/registry.bin
fail() { echo "gst-launch-test: $*"; exit 1; }
. "$root/gst/tests/same-frames.sh"

# 1. gst-inspect-1.0: exit 0, nothing on stderr, no warning in what it prints.
gst-inspect-1.0 defocus >"$work/inspect.txt" 2>"$work/inspect.err" || fail "gst-inspect-1.0 defocus failed"
[ ! -s "$work/inspect.err" ] || fail "gst-inspect-1.0 wrote to stderr: $(cat "$work/inspect.err")"
! grep -qE "WARNING|CRITICAL|WARN " "$work/inspect.txt" || fail "gst-inspect-1.0 output has warnings"
for property in focus f-number focal-length sensor-width fov-from max-coc coc-model near far quality samples \
  hexagon precision resolution near-field highlight-sprites highlight-gain blade-rotation depth-scale view \
  autofocus autofocus-time-constant post-timings; do
  grep -q "^  $property *:" "$work/inspect.txt" || fail "property $property missing"
done
grep -q "Klass  *Filter/Effect/Video" "$work/inspect.txt" || fail "classification is not Filter/Effect/Video"

# 2. The bundled clip through gst-launch-1.0, numbered as multifilesrc needs (the TUM files are
# named by timestamp), paired as the CLI pairs them (associations.txt).
mkdir -p "$work/rgb" "$work/depth"
i=0
while read -r _ rgb _ depth; do
  n=$(printf %06d $i)
  ln -s "$root/data/tum_fr1_rpy/$rgb" "$work/rgb/$n.png"
  ln -s "$root/data/tum_fr1_rpy/$depth" "$work/depth/$n.png"
  i=$((i + 1))
done <"$root/data/tum_fr1_rpy/associations.txt"
inputs=$i
lens="--focus 1.0 --f-number 1.4"
for variant in "balanced" "high --hexagon mcintosh"; do
  read -r preset extra <<<"$variant"
  props="autofocus=false focus=1.0 f-number=1.4 depth-scale=5000 quality=$preset"
  [ -n "${extra:-}" ] && props="$props hexagon=mcintosh"
  rm -rf "$work/gst" "$work/cli" && mkdir -p "$work/gst"
  gst-launch-1.0 -q defocus name=d $props ! videoconvert ! pngenc ! multifilesink location="$work/gst/%06d.png" \
    multifilesrc location="$work/rgb/%06d.png" caps=image/png,framerate=30/1 ! pngdec ! d.color \
    multifilesrc location="$work/depth/%06d.png" caps=image/png,framerate=30/1 ! pngdec ! d.depth \
    || fail "the pipeline failed ($variant)"
  "$cli" "$root/data/tum_fr1_rpy" -o "$work/cli/" $lens --quality $preset ${extra:-} -q >/dev/null
  same_frames_as_cli "$work/gst" "$work/cli" "$work" "gst-launch-1.0 ($variant)"
  [ "$frames" -eq "$inputs" ] || fail "$frames frames out of $inputs in ($variant)"
  echo "gst-launch-test: $frames frames from gst-launch-1.0 = defocus CLI, byte for byte ($variant)"
done

# 3. No OpenGL (no EGL vendor library): an error message from the element, exit 1, no crash.
set +e
__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json gst-launch-1.0 -q defocus name=d ! fakesink \
  multifilesrc location="$work/rgb/%06d.png" caps=image/png,framerate=30/1 num-buffers=1 ! pngdec ! d.color \
  multifilesrc location="$work/depth/%06d.png" caps=image/png,framerate=30/1 num-buffers=1 ! pngdec ! d.depth \
  >"$work/nogl.txt" 2>&1
status=$?
set -e
[ $status -eq 1 ] || fail "without GL gst-launch-1.0 exited $status, not 1: $(cat "$work/nogl.txt")"
grep -q "No OpenGL 4.5 for the defocus filter" "$work/nogl.txt" || fail "without GL: $(cat "$work/nogl.txt")"
echo "gst-launch-test: without OpenGL the pipeline stops with the element's error"
