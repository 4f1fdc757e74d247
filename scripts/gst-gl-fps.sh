#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Frames per second of the `defocus` element in system memory and in GL memory, in one run: the
# bundled clip's frame 9 and its depth at SIZE (640x480 as they are; other sizes through
# videoscale, nearest neighbour for the depth), N times over (imagefreeze), through
#   system:  pngdec ! videoconvert ! RGBA ! defocus ! fakesink
#   gl:      pngdec ! videoconvert ! RGBA ! glupload ! defocus ! fakesink          (stays on the GPU)
#   gl+down: ... ! glupload ! defocus ! gldownload ! fakesink                      (back to RAM)
# each run twice, alternating, the faster kept; wall time from gst-launch-1.0's "Execution ended
# after". With no DISPLAY the GL runs use the element's headless EGL display.
#   scripts/gst-gl-fps.sh BUILD_DIR [FRAMES=60] [SIZE=640x480]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$1
frames=${2:-60}
size=${3:-640x480}
width=${size%x*} height=${size#*x}
[[ $width =~ ^[0-9]+$ && $height =~ ^[0-9]+$ ]] || { echo "gst-gl-fps: error: SIZE '$size' is not WxH" >&2; exit 2; }
export GST_PLUGIN_PATH=$build/gst GST_REGISTRY=${TMPDIR:-/tmp}/gst-gl-fps-registry.bin
read -r _ rgb _ depth < <(sed -n 9p "$root/data/tum_fr1_rpy/associations.txt")
clip=$root/data/tum_fr1_rpy

seconds() { # UP DOWN: one run's wall time, seconds
  local up=$1 down=$2 out
  # shellcheck disable=SC2086 # $up and $down are elements or nothing
  out=$(gst-launch-1.0 defocus name=d depth-scale=5000 autofocus=false focus=1.0 f-number=1.4 ! $down fakesink \
    filesrc location="$clip/$rgb" ! pngdec ! imagefreeze num-buffers="$frames" ! videoconvert ! videoscale ! \
    video/x-raw,format=RGBA,width="$width",height="$height" ! $up d.color \
    filesrc location="$clip/$depth" ! pngdec ! imagefreeze num-buffers="$frames" ! videoconvert ! \
    videoscale method=nearest-neighbour ! video/x-raw,format=GRAY16_LE,width="$width",height="$height" ! \
    $up d.depth 2>&1) || { echo "$out" >&2; exit 1; }
  echo "$out" | sed -n 's/^Execution ended after \([0-9]*\):\([0-9]*\):\([0-9.]*\)$/\1 \2 \3/p' |
    awk '{ printf "%.3f\n", $1 * 3600 + $2 * 60 + $3 }'
}

declare -A best
for round in 1 2; do
  for mode in system gl gl+down; do
    case $mode in
      system) t=$(seconds "" "") ;;
      gl) t=$(seconds "glupload !" "") ;;
      gl+down) t=$(seconds "glupload !" "gldownload !") ;;
    esac
    if [ -z "${best[$mode]:-}" ] || awk -v a="$t" -v b="${best[$mode]}" 'BEGIN { exit !(a < b) }'; then
      best[$mode]=$t
    fi
  done
done
renderer=$(GST_DEBUG=defocus:4 gst-launch-1.0 defocus name=d ! fakesink \
  filesrc location="$clip/$rgb" ! pngdec ! imagefreeze num-buffers=1 ! d.color \
  filesrc location="$clip/$depth" ! pngdec ! imagefreeze num-buffers=1 ! d.depth 2>&1 |
  sed -n 's/.*filtering on \(.*\)$/\1/p' | head -1)
echo "defocus element, $frames frames of $size, on ${renderer:-an unknown renderer}:"
for mode in system gl gl+down; do
  awk -v m="$mode" -v t="${best[$mode]}" -v n="$frames" 'BEGIN { printf "  %-8s %6.1f fps (%.2f s)\n", m, n / t, t }'
done
