#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# The defocussrc element from the command line: gst-inspect-1.0 describes it cleanly; the bundled
# TUM folder read by defocussrc (files named by timestamp, which multifilesrc cannot read) and
# filtered by defocus gives the CLI's frames, byte for byte; num-buffers stops it; a missing input
# is an error naming it, not a crash.
#   gst/tests/defocussrc-test.sh BUILD_DIR DEFOCUS_CLI
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$1 cli=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export GST_PLUGIN_PATH=$build/gst GST_REGISTRY=$work/registry.bin
fail() { echo "defocussrc-test: $*"; exit 1; }
. "$root/gst/tests/same-frames.sh"
clip=$root/data/tum_fr1_rpy

# 1. gst-inspect-1.0: exit 0, nothing on stderr, no warning, both pads and the properties.
gst-inspect-1.0 defocussrc >"$work/inspect.txt" 2>"$work/inspect.err" || fail "gst-inspect-1.0 defocussrc failed"
[ ! -s "$work/inspect.err" ] || fail "gst-inspect-1.0 wrote to stderr: $(cat "$work/inspect.err")"
! grep -qE "WARNING|CRITICAL|WARN " "$work/inspect.txt" || fail "gst-inspect-1.0 output has warnings"
for property in location depth-location input-depth-scale depth-scale width height fps num-buffers read-threads; do
  grep -q "^  $property *:" "$work/inspect.txt" || fail "property $property missing"
done
for pad in color depth; do
  grep -q "SRC template: '$pad'" "$work/inspect.txt" || fail "no src pad template '$pad'"
done
grep -q "Klass  *Source/Video" "$work/inspect.txt" || fail "classification is not Source/Video"

# 2. The TUM folder through defocussrc and defocus, against the CLI on the same folder. The
# depth pad carries the clip's own units (5000 per metre), so nothing is rounded on the way.
mkdir -p "$work/gst" "$work/cli"
gst-launch-1.0 -q defocussrc name=s location="$clip" depth-scale=5000 \
  defocus name=d autofocus=false focus=1.0 f-number=1.4 depth-scale=5000 ! videoconvert ! pngenc ! \
  multifilesink location="$work/gst/%06d.png" \
  s.color ! queue ! d.color  s.depth ! queue ! d.depth || fail "the pipeline failed"
"$cli" "$clip" -o "$work/cli/" --focus 1.0 --f-number 1.4 -q >/dev/null
same_frames_as_cli "$work/gst" "$work/cli" "$work" "defocussrc ! defocus"
echo "defocussrc-test: $frames frames of the TUM folder through defocussrc ! defocus = defocus CLI, byte for byte"
# The same with the clip decoded on three threads ahead of the streaming thread: the property
# reaches the source (its info line) and the frames are the same, in order.
mkdir -p "$work/gst3"
GST_DEBUG=defocussrc:4 gst-launch-1.0 -q defocussrc name=s location="$clip" depth-scale=5000 read-threads=3 \
  defocus name=d autofocus=false focus=1.0 f-number=1.4 depth-scale=5000 ! videoconvert ! pngenc ! \
  multifilesink location="$work/gst3/%06d.png" \
  s.color ! queue ! d.color  s.depth ! queue ! d.depth >/dev/null 2>"$work/threads.log" || fail "read-threads=3 failed"
grep -q "decoded on 3 thread(s) ahead" "$work/threads.log" || fail "read-threads=3 did not reach the source"
same_frames_as_cli "$work/gst3" "$work/cli" "$work" "defocussrc read-threads=3 ! defocus"
echo "defocussrc-test: read-threads=3 gives the same $frames frames"

# 3. num-buffers: that many frames on each pad, then the end of the stream.
gst-launch-1.0 -q defocussrc name=s location="$clip" num-buffers=3 \
  s.color ! queue ! multifilesink location="$work/n-color-%02d.raw" \
  s.depth ! queue ! multifilesink location="$work/n-depth-%02d.raw" \
  2>"$work/n.err" >/dev/null || fail "num-buffers=3: $(cat "$work/n.err")"
for pad in color depth; do
  [ "$(ls "$work"/n-$pad-*.raw | wc -l)" -eq 3 ] || fail "num-buffers=3 gave $(ls "$work"/n-$pad-*.raw | wc -l) $pad buffers"
done
# GRAY16_LE at 640x480 (the clip's depth size), BGR at 640x480.
[ "$(stat -c %s "$work/n-depth-00.raw")" -eq $((640 * 480 * 2)) ] || fail "a depth buffer is not 640x480 GRAY16"
[ "$(stat -c %s "$work/n-color-00.raw")" -eq $((640 * 480 * 3)) ] || fail "a colour buffer is not 640x480 BGR"
echo "defocussrc-test: num-buffers=3 gives 3 frames on each pad"
# The depth pad at the clip's own 5000 units per metre holds the PNG's values, little-endian:
# catches a wrong scale, byte order or rounding on the way from metres back to units.
gst-launch-1.0 -q defocussrc name=s location="$clip" depth-scale=5000 num-buffers=1 s.depth ! queue ! \
  filesink location="$work/src-depth.raw" s.color ! queue ! fakesink
read -r _ _ _ depth0 <"$clip/associations.txt"
gst-launch-1.0 -q filesrc location="$clip/$depth0" ! pngdec ! videoconvert ! video/x-raw,format=GRAY16_LE ! \
  filesink location="$work/png-depth.raw"
cmp -s "$work/src-depth.raw" "$work/png-depth.raw" || fail "the depth pad differs from $depth0 at 5000 units per metre"
echo "defocussrc-test: the depth pad holds $depth0's values at depth-scale=5000"

# 4. A missing input: the state change fails with the source's message naming it.
set +e
gst-launch-1.0 -q defocussrc name=s location="$work/nonexistent" s.color ! fakesink s.depth ! fakesink \
  >"$work/missing.txt" 2>&1
status=$?
set -e
# gst-launch-1.0 exits 255 when the pipeline cannot start (1 for an error while it runs).
[ $status -eq 255 ] || fail "a missing input exited $status, not 255: $(cat "$work/missing.txt")"
grep -q "$work/nonexistent" "$work/missing.txt" || fail "the error does not name the input: $(cat "$work/missing.txt")"
echo "defocussrc-test: a missing input is the element's error, naming it"
