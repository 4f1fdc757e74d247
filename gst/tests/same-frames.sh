# SPDX-License-Identifier: LGPL-2.1-or-later
# Sourced by the gst tests: same_frames_as_cli GST_DIR CLI_DIR WORK WHAT
# GST_DIR holds a pipeline's frames as %06d.png, CLI_DIR the defocus CLI's folder output (frames
# under the clip's TUM names, listed in rgb.txt). Both sets are decoded to raw RGB by the same
# decoder and must be the same bytes and as many frames; sets `frames` to the count. Calls the
# sourcing script's fail() on a difference.
same_frames_as_cli() {
  local gst=$1 cli=$2 work=$3 what=$4 n=0 file
  rm -rf "$work/cli-seq" && mkdir -p "$work/cli-seq"
  # Numbered links in rgb.txt's order, for multifilesrc.
  while read -r _ file; do
    ln -s "$cli/$file" "$work/cli-seq/$(printf %06d $n).png"
    n=$((n + 1))
  done < <(grep -v '^#' "$cli/rgb.txt")
  frames=$n
  [ "$(ls "$gst" | wc -l)" -eq "$frames" ] || fail "$what gave $(ls "$gst" | wc -l) frames, not $frames"
  gst-launch-1.0 -q multifilesrc location="$gst/%06d.png" caps=image/png,framerate=30/1 ! pngdec ! \
    videoconvert ! video/x-raw,format=RGB ! filesink location="$work/gst.rgb"
  gst-launch-1.0 -q multifilesrc location="$work/cli-seq/%06d.png" caps=image/png,framerate=30/1 ! pngdec ! \
    videoconvert ! video/x-raw,format=RGB ! filesink location="$work/cli.rgb"
  [ -s "$work/cli.rgb" ] || fail "no CLI frames decoded"
  cmp -s "$work/gst.rgb" "$work/cli.rgb" || fail "$what: frames differ from the CLI's"
}
