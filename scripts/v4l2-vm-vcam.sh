#!/bin/bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# The virtual camera, inside the VM of scripts/v4l2-vm-test.sh (v4l2loopback nodes /dev/video4,
# /dev/video5, and /dev/video6 for v4l2sink alone): the command line writes INPUT (3 frames of the
# bundled clip at half size, made by `v4l2-vcam-check prepare`: INPUT/rgb/%06d.png,
# INPUT/depth/%06d.png) to PNGs (the reference), then to /dev/video4 while v4l2-vcam-check captures that node as a webcam reader would and compares
# each frame with the reference in YUYV (tests/v4l2_vcam_check.cpp states the bound). With GST=1
# the same through gst-launch-1.0 ... ! defocus ! videoconvert ! v4l2sink on /dev/video5; with
# GST=only that alone (no defocus -o /dev/video4).
#   scripts/v4l2-vm-vcam.sh BUILD_DIR INPUT GST
set -u
build=$1 input=$2 gst=${3:-0}
in=("$input/rgb" --depth "$input/depth" --depth-scale 5000)
lens=(--focus 1.0 --f-number 1.4 --quality fast)
ref=/dev/shm/vcam-ref
say() { echo "  vcam: $*"; }
now() { cut -d' ' -f1 /proc/uptime; }
status=0

mkdir -p $ref
t=$(now)
if ! "$build/defocus" "${in[@]}" "${lens[@]}" -q -o $ref/ >/dev/shm/vcam-ref.log 2>&1; then
  say "the reference run failed:"; sed 's/^/    /' /dev/shm/vcam-ref.log; exit 1
fi
# The command line's sequence keeps the input's frame names (listed in rgb.txt): the reader takes
# a folder of them alone, in order.
mkdir -p $ref-frames
n=0
# (No process substitution: the VM's init mounts no /dev/fd.)
grep -v '^#' $ref/rgb.txt >/dev/shm/vcam-ref-list.txt
while read -r _ file; do
  ln -sf "$ref/$file" "$ref-frames/$(printf %06d $n).png"
  n=$((n + 1))
done </dev/shm/vcam-ref-list.txt
say "reference: $n PNGs ($t -> $(now) s)"
ref=$ref-frames

# 1. defocus -o /dev/video4
if [ "$gst" != only ]; then
rm -f /dev/shm/vcam-done
"$build/tests/v4l2-vcam-check" /dev/video4 $ref pair 600 /dev/shm/vcam-done >/dev/shm/vcam-check.log 2>&1 &
reader=$!
t=$(now)
"$build/defocus" "${in[@]}" "${lens[@]}" -o /dev/video4 >/dev/shm/vcam-cli.log 2>&1
cli=$?
touch /dev/shm/vcam-done
wait $reader
check=$?
tr '\r' '\n' </dev/shm/vcam-cli.log | grep -v '^frame' | sed 's/^/    /'
sed 's/^/    /' /dev/shm/vcam-check.log
say "defocus -o /dev/video4: exit $cli, reader exit $check ($t -> $(now) s)"
[ $cli = 0 ] && [ $check = 0 ] || status=1
fi

# 2. gst-launch-1.0 ... ! defocus ! videoconvert ! v4l2sink device=/dev/video5 (opt-in: with
# v4l2loopback 0.12.7 v4l2sink often hangs at NULL, v4l2loopback's bug, docs/v4l2.md; frames
# flow with the default io-mode and are checked, and a hang fails this part on exit 124).
if [ "$gst" = 1 ] || [ "$gst" = only ]; then
  # Only the plugins the pipeline needs: scanning all of them takes minutes under emulation.
  plugins=/dev/shm/gst-plugins
  mkdir -p $plugins
  ln -sf "$build/gst/libgstdefocus.so" $plugins/
  for p in coreelements multifile png videoconvertscale video4linux2 videotestsrc; do
    ln -sf "/usr/lib/x86_64-linux-gnu/gstreamer-1.0/libgst$p.so" $plugins/
  done
  export GST_PLUGIN_SYSTEM_PATH_1_0=$plugins GST_PLUGIN_PATH_1_0= GST_REGISTRY_1_0=/dev/shm/registry.bin GST_DEBUG=2 \
    GST_DEBUG_NO_COLOR=1
  # v4l2sink alone (no GL: seconds): 124 is a hang. On /dev/video6 and on /dev/video3 (free after
  # the probe), so that one boot compares a node with exclusive_caps (DEFOCUS_V4L2_VM_LOOPBACK)
  # and one without; 30 frames as a clip plays, 3 with the properties of the pipeline below; and
  # io-mode=rw (v4l2loopback 0.12.7 has no USERPTR or DMABUF: mmap, io-mode auto, and rw are all
  # it takes). GStreamer's own check of the driver, "buffer N was not queued, this indicate a
  # driver bug", is counted.
  say "v4l2loopback exclusive_caps: $(cat /sys/module/v4l2loopback/parameters/exclusive_caps 2>/dev/null)"
  for run in "video6 30 auto" "video3 30 auto" "video6 3 auto show-preroll-frame=false sync=false" "video6 30 rw"; do
    set -- $run
    node=$1 buffers=$2 mode=$3
    shift 3
    t=$(now)
    timeout 60 gst-launch-1.0 videotestsrc num-buffers=$buffers ! video/x-raw,width=320,height=240,framerate=30/1 ! \
      videoconvert ! video/x-raw,format=YUY2 ! v4l2sink device=/dev/$node io-mode=$mode "$@" \
      >/dev/shm/vcam-testsrc.log 2>&1
    say "videotestsrc num-buffers=$buffers ! v4l2sink device=/dev/$node io-mode=$mode $*: exit $? ($t -> $(now) s)," \
      "$(grep -c 'was not queued' /dev/shm/vcam-testsrc.log) 'buffer was not queued' errors"
    grep -v '^0:00' /dev/shm/vcam-testsrc.log | tail -n 2 | sed 's/^/      /'
  done
  # Which element a hang at NULL waits in: GST_STATES logs each element's state changes.
  export GST_DEBUG=2,GST_STATES:4
  rm -f /dev/shm/vcam-done
  "$build/tests/v4l2-vcam-check" /dev/video5 $ref left 600 /dev/shm/vcam-done >/dev/shm/vcam-gst-check.log 2>&1 &
  reader=$!
  t=$(now)
  timeout 400 gst-launch-1.0 \
    defocus name=d autofocus=false focus=1.0 f-number=1.4 depth-scale=5000 quality=fast ! \
    videoconvert chroma-mode=none dither=none ! video/x-raw,format=YUY2 ! \
    v4l2sink device=/dev/video5 show-preroll-frame=false sync=false \
    multifilesrc location=$input/rgb/%06d.png caps=image/png,framerate=30/1 ! pngdec ! d.color \
    multifilesrc location=$input/depth/%06d.png caps=image/png,framerate=30/1 ! pngdec ! d.depth \
    >/dev/shm/vcam-gst.log 2>&1
  launch=$?
  touch /dev/shm/vcam-done
  wait $reader
  check=$?
  grep -v GST_STATES /dev/shm/vcam-gst.log | sed 's/^/    /' | tail -n 30
  echo "    the last state changes:"
  grep GST_STATES /dev/shm/vcam-gst.log | tail -n 8 | sed 's/^.*GST_STATES //; s/^/      /'
  sed 's/^/    /' /dev/shm/vcam-gst-check.log
  say "gst-launch-1.0 ... ! v4l2sink device=/dev/video5: exit $launch, reader exit $check ($t -> $(now) s)," \
    "$(grep -c 'was not queued' /dev/shm/vcam-gst.log) 'buffer was not queued' errors"
  [ $launch = 0 ] && [ $check = 0 ] || status=1
fi
exit $status
