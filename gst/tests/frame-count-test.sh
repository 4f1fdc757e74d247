#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# One frame out per colour frame from the command line: the bundled TUM clip with frames taken out
# of rgb.txt (a recording with gaps) through defocussrc ! defocus ! multifilesink gives one file
# per colour frame, at a variable rate (framerate=0/1), where a mean rate made the aggregator fill
# the gaps with repeats; a constant-rate input stays at its rate; and `gst-launch-1.0 -q ... !
# fdsink` writes the video and nothing else (the library's warnings are not on stdout).
#   gst/tests/frame-count-test.sh BUILD_DIR
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export GST_PLUGIN_PATH=$build/gst GST_REGISTRY=$work/registry.bin
fail() { echo "frame-count-test: $*"; exit 1; }
clip=$root/data/tum_fr1_rpy

# The clip without its 3rd, 4th and 8th colour frames (rgb.txt), and without depth for the 6th
# colour frame (depth.txt), which the library warns about.
mkdir -p "$work/gaps"
ln -s "$clip/rgb" "$work/gaps/rgb"
ln -s "$clip/depth" "$work/gaps/depth"
awk '/^#/ { print; next } { n++ } n != 3 && n != 4 && n != 8' "$clip/rgb.txt" >"$work/gaps/rgb.txt"
awk '/^#/ { print; next } { n++ } n != 6' "$clip/depth.txt" >"$work/gaps/depth.txt"
colour=$(grep -vc '^#' "$work/gaps/rgb.txt")

pipeline() { # LOCATION SINK...: defocussrc ! defocus ! videoconvert ! RGB ! SINK
  local location=$1
  shift
  gst-launch-1.0 -q defocussrc name=s location="$location" depth-scale=5000 \
    defocus name=d autofocus=false focus=1.0 depth-scale=5000 ! videoconvert ! video/x-raw,format=RGB ! "$@" \
    s.color ! queue ! d.color s.depth ! queue ! d.depth
}

# 1. One PNG per colour frame.
mkdir -p "$work/png"
pipeline "$work/gaps" pngenc ! multifilesink location="$work/png/%06d.png" || fail "the pipeline failed"
out=$(ls "$work/png" | wc -l)
[ "$out" -eq "$colour" ] || fail "$out frames out for $colour colour frames in"
echo "frame-count-test: $out frames out for $colour colour frames of a clip with gaps"

# 2. Variable rate for the clip with gaps; a constant-rate input keeps its rate.
gst-launch-1.0 -v defocussrc name=s location="$work/gaps" depth-scale=5000 num-buffers=2 \
  defocus name=d autofocus=false ! fakesink s.color ! queue ! d.color s.depth ! queue ! d.depth >"$work/v.txt" 2>&1 ||
  fail "the -v pipeline failed: $(tail -5 "$work/v.txt")"
grep -q "/GstDefocus:d.GstAggregatorPad:src: caps = .*framerate=(fraction)0/1" "$work/v.txt" ||
  fail "the clip with gaps is not variable rate: $(grep 'd.GstAggregatorPad:src: caps' "$work/v.txt")"
read -r _ rgb0 _ depth0 <"$clip/associations.txt"
gst-launch-1.0 -v defocus name=d autofocus=false ! fakesink \
  multifilesrc location="$clip/$rgb0" caps=image/png,framerate=30/1 num-buffers=3 ! pngdec ! d.color \
  multifilesrc location="$clip/$depth0" caps=image/png,framerate=30/1 num-buffers=3 ! pngdec ! d.depth \
  >"$work/c.txt" 2>&1 || fail "the constant-rate pipeline failed: $(tail -5 "$work/c.txt")"
grep -q "/GstDefocus:d.GstAggregatorPad:src: caps = .*framerate=(fraction)30/1" "$work/c.txt" ||
  fail "a 30/1 input does not stay 30/1: $(grep 'd.GstAggregatorPad:src: caps' "$work/c.txt")"
echo "frame-count-test: the clip with gaps is variable rate (0/1), a 30/1 input stays 30/1"

# 3. fdsink: stdout is exactly the video filesink writes (the library warns about the frame
# without depth on its debug category and as an element warning, not on stdout).
pipeline "$work/gaps" fdsink fd=1 >"$work/stdout.rgb" 2>"$work/stderr.txt" || fail "fdsink: $(cat "$work/stderr.txt")"
pipeline "$work/gaps" filesink location="$work/file.rgb" 2>/dev/null || fail "filesink pipeline failed"
[ "$(stat -c %s "$work/file.rgb")" -eq $((colour * 640 * 480 * 3)) ] || fail "filesink wrote $(stat -c %s "$work/file.rgb") bytes"
cmp -s "$work/stdout.rgb" "$work/file.rgb" ||
  fail "stdout is not the video alone: $(grep -a -m3 'defocus\|warning' "$work/stdout.rgb" | cut -c1-200)"
GST_DEBUG=defocuslib:4 pipeline "$work/gaps" fakesink >/dev/null 2>"$work/debug.txt" || true
grep -q "defocuslib.*no depth" "$work/debug.txt" ||
  fail "the library's warning is not on the defocuslib category: $(grep -m3 defocuslib "$work/debug.txt")"
echo "frame-count-test: fdsink writes the video alone; the library's warning goes to GST_DEBUG=defocuslib"
