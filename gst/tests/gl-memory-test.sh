#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# GL memory through the element: the bundled clip with gaps (frames taken out of rgb.txt) through
# defocussrc, uploaded (glupload), filtered in GL memory and downloaded (gldownload), gives the same
# frames, byte for byte, as many and with the same timestamps and durations as the system-memory
# pipeline; with no display at all (the element offers GStreamer's GL library its headless EGL
# display) and, where Xvfb is installed, on an X display (GLX, GStreamer's own display).
# Defects caught: a GL path that renders another image (channels swapped, depth bytes misread, the
# filter's settings not the system path's), drops or repeats frames, or loses their timestamps; no
# GL pipeline at all without a display.
#   gst/tests/gl-memory-test.sh BUILD_DIR
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$1
work=$(mktemp -d)
xvfb=""
cleanup() {
  [ -z "$xvfb" ] || kill "$xvfb" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
export GST_PLUGIN_PATH=$build/gst GST_REGISTRY=$work/registry.bin
fail() { echo "gl-memory-test: $*"; exit 1; }
gst-inspect-1.0 glupload >/dev/null 2>&1 || { echo "gl-memory-test: no glupload (gstreamer1.0-gl): skipped"; exit 0; }
clip=$root/data/tum_fr1_rpy

mkdir -p "$work/gaps"
ln -s "$clip/rgb" "$work/gaps/rgb"
ln -s "$clip/depth" "$work/gaps/depth"
cp "$clip/depth.txt" "$work/gaps/depth.txt"
awk '/^#/ { print; next } { n++ } n != 3 && n != 4 && n != 8' "$clip/rgb.txt" >"$work/gaps/rgb.txt"
colour=$(grep -vc '^#' "$work/gaps/rgb.txt")

run() { # NAME MEMORY(gl|system): frames as NAME/%06d.png, each buffer's timestamps in NAME.ts
  local name=$1 up="" down=""
  [ "$2" = gl ] && up="glupload !" down="gldownload !"
  mkdir -p "$work/$name"
  # shellcheck disable=SC2086 # $up and $down are elements or nothing
  gst-launch-1.0 -v defocussrc name=s location="$work/gaps" depth-scale=5000 \
    defocus name=d depth-scale=5000 ! $down identity name=stamp silent=false ! videoconvert ! \
    video/x-raw,format=RGB ! pngenc ! multifilesink location="$work/$name/%06d.png" \
    s.color ! queue ! videoconvert ! video/x-raw,format=RGBA ! $up d.color \
    s.depth ! queue ! $up d.depth >"$work/$name.log" 2>&1 ||
    fail "$name: gst-launch-1.0 exited $?: $(grep -m3 -i error "$work/$name.log"; grep -v 'last-message' "$work/$name.log" | tail -n 8)"
  grep -o 'stamp: last-message = chain.*' "$work/$name.log" | grep -o 'pts: [^,]*, duration: [^,]*' \
    >"$work/$name.ts" || true
}

compare() { # NAME: NAME's frames and timestamps are the system-memory pipeline's
  local name=$1 f
  [ "$(ls "$work/$name" | wc -l)" -eq "$colour" ] || fail "$name: $(ls "$work/$name" | wc -l) frames for $colour"
  [ "$(wc -l <"$work/$name.ts")" -eq "$colour" ] || fail "$name: $(wc -l <"$work/$name.ts") timestamps for $colour"
  cmp -s "$work/$name.ts" "$work/system.ts" || fail "$name: timestamps differ: $(diff "$work/$name.ts" "$work/system.ts" | head -4)"
  for f in "$work/system"/*.png; do
    cmp -s "$f" "$work/$name/$(basename "$f")" || fail "$name: frame $(basename "$f") differs from system memory's"
  done
  echo "gl-memory-test: $name: $colour frames, the same bytes and timestamps as system memory"
}

(unset DISPLAY WAYLAND_DISPLAY; run system system)
[ "$(wc -l <"$work/system.ts")" -eq "$colour" ] || fail "system memory: $(wc -l <"$work/system.ts") timestamps"

# 1. No display: GStreamer's GL library gets the element's headless EGL display.
(unset DISPLAY WAYLAND_DISPLAY; run headless gl)
grep -q 'Got context from element .d.: gst.gl.GLDisplay=.*GstGLDisplayEGL' "$work/headless.log" ||
  fail "headless: the element offered no EGL display: $(grep -m2 'context' "$work/headless.log")"
compare headless

# 2. An X display (Xvfb), where GStreamer opens its own (GLX).
if command -v Xvfb >/dev/null; then
  # The server picks a free display and writes its number when it listens (-displayfd): tests
  # that start their own Xvfb side by side cannot take the same one.
  Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp 3>"$work/display" >/dev/null 2>&1 &
  xvfb=$!
  for _ in $(seq 100); do [ -s "$work/display" ] && break; sleep 0.1; done
  n=$(head -n 1 "$work/display")
  [ -n "$n" ] || { echo "gl-memory-test: Xvfb did not start" >&2; exit 1; }
  (export DISPLAY=":$n"; unset WAYLAND_DISPLAY; run xvfb gl)
  compare xvfb
else
  echo "gl-memory-test: no Xvfb: the X display case skipped"
fi
