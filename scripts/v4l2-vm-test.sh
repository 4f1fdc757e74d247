#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Runs the V4L2 capture probe (tests/v4l2_vm_probe.cpp) against real kernel drivers in a small
# qemu VM: Debian's own kernel with vivid (colour formats) and v4l2loopback (Z16, MJPEG), the
# host root shared read-only over 9p. Facts behind each step: docs/v4l2.md.
#   scripts/v4l2-vm-test.sh PROBE [CACHE_DIR]     (CTest: ctest -L v4l2)
# Exit: 0 passed, 1 failed, 77 skipped (the VM cannot run here: no root to install packages, no
# network for the first download, no qemu; or v4l2loopback did not build, so its tests did not run). Downloads (~85 MB, once) go to CACHE_DIR (default:
# v4l2-vm/ beside PROBE); nothing is installed but the packages below, and the kernel never is.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
probe=$(readlink -f "${1:?usage: $0 PROBE [CACHE_DIR]}")
cache=$(mkdir -p "${2:-$(dirname "$probe")/v4l2-vm}" && cd "${2:-$(dirname "$probe")/v4l2-vm}" && pwd)
start=$(date +%s.%N)

say() { printf 'v4l2-vm-test: %s\n' "$*"; }
skip() { say "SKIP: $*"; exit 77; }
fail() { say "FAIL: $*"; exit 1; }
elapsed() { awk -v a="$1" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }

[ "$(uname -m)" = x86_64 ] || skip "needs an x86-64 host"
[ -x "$probe" ] || fail "no probe binary at $probe"
exec 9>"$cache/.lock"
flock 9 # one run at a time per cache

# ---- host packages, installed only when missing (the pattern of scripts/setup.sh) ----
# qemu-system-x86: the VM; busybox-static: the initramfs's only program (sh, modprobe, depmod,
# cpio); v4l-utils: v4l2-ctl for the device list in the log; xz-utils: unpacks vmlinux from
# vmlinuz (booting it saves ~3 s under TCG); make, gcc-12, patch: build v4l2loopback.
packages=(qemu-system-x86 busybox-static v4l-utils xz-utils make gcc-12 patch)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null && sudo -n true 2>/dev/null || skip "needs ${missing[*]}; no root to install them"
    sudo="sudo -n"
  fi
  say "installing ${missing[*]}"
  { $sudo apt-get update -q && $sudo env DEBIAN_FRONTEND=noninteractive \
      apt-get install -y -q --no-install-recommends "${missing[@]}"; } >"$cache/apt.log" 2>&1 ||
    skip "could not install ${missing[*]} (see $cache/apt.log)"
fi

# ---- the kernel linux-image-amd64 points at, and its headers: downloaded and unpacked once ----
# A kernel already unpacked here is kept (runs stay reproducible and work offline); delete
# CACHE_DIR/kernel-* to move to the kernel the archive has now.
kdir=$(ls -d "$cache"/kernel-*/.unpacked 2>/dev/null | sort -V | tail -n 1 || true)
kdir=${kdir%/.unpacked}
if [ -n "$kdir" ]; then
  kver=$(ls "$kdir/root/lib/modules")
else
  image=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ { print $2; exit }')
  [ -n "$image" ] || skip "apt-cache knows no linux-image-amd64 (no package lists?)"
  kver=${image#linux-image-}                                  # e.g. 6.1.0-56-amd64
  pkgver=$(apt-cache policy "$image" | awk '/Candidate:/ { print $2 }')
  kdir="$cache/kernel-$kver-$pkgver"
fi
kroot="$kdir/root"
if [ ! -e "$kdir/.unpacked" ]; then
  say "downloading $image $pkgver, its headers and v4l2loopback-dkms into $kdir"
  rm -rf "$kdir" && mkdir -p "$kdir/debs"
  headers="linux-headers-$kver"
  # The headers need the common headers and kbuild of the same kernel source version.
  debs=("$image=$pkgver" "$headers=$pkgver" v4l2loopback-dkms)
  for dep in $(apt-cache depends "$headers" | awk '/Depends: linux-(headers|kbuild)-/ { print $2 }'); do
    debs+=("$dep=$pkgver")
  done
  (cd "$kdir/debs" && apt-get download "${debs[@]}") \
    >"$kdir/download.log" 2>&1 || skip "apt-get download failed (offline?), see $kdir/download.log"
  for deb in "$kdir"/debs/*.deb; do dpkg -x "$deb" "$kroot"; done
  rm -rf "$kdir/debs"
  # The package ships no modules.dep; busybox depmod writes one (~8 s, once).
  busybox depmod -b "$kroot" "$kver"
  # The headers' Makefile includes the common headers by absolute path: point it at this tree.
  sed -i "s|^include /usr/src/|include $kroot/usr/src/|" "$kroot/usr/src/linux-headers-$kver/Makefile"
  touch "$kdir/.unpacked"
fi
moddir="$kroot/lib/modules/$kver"

# Under TCG the bzImage's self-decompression costs ~3 s: boot the ELF vmlinux (PVH entry).
kernel="$kroot/boot/vmlinuz-$kver"
if [ ! -s "$kdir/vmlinux" ]; then
  offset=$(LC_ALL=C grep -obUaP '\xfd7zXZ\x00' "$kernel" | head -n 1 | cut -d: -f1 || true)
  if [ -n "$offset" ]; then
    tail -c +$((offset + 1)) "$kernel" | xz -dc --single-stream >"$kdir/vmlinux.part" 2>/dev/null || true
    [ "$(head -c 4 "$kdir/vmlinux.part" | od -An -c | tr -d ' ')" = '177ELF' ] && mv "$kdir/vmlinux.part" "$kdir/vmlinux"
    rm -f "$kdir/vmlinux.part"
  fi
fi
[ -s "$kdir/vmlinux" ] && kernel="$kdir/vmlinux"

# ---- v4l2loopback with Z16 (scripts/v4l2loopback-z16.patch), against the same kernel ----
patchfile="$root/scripts/v4l2loopback-z16.patch"
loopback="$kdir/v4l2loopback/v4l2loopback.ko"
stamp="$(sha256sum "$patchfile" | cut -c1-16)"
if [ ! -s "$loopback" ] || [ "$(cat "$kdir/v4l2loopback/.patch" 2>/dev/null)" != "$stamp" ]; then
  say "building v4l2loopback for $kver"
  rm -rf "$kdir/v4l2loopback"
  cp -r "$(ls -d "$kroot"/usr/src/v4l2loopback-* | head -n 1)" "$kdir/v4l2loopback"
  if patch -s -d "$kdir/v4l2loopback" -p1 <"$patchfile" &&
    make -C "$kroot/usr/src/linux-headers-$kver" M="$kdir/v4l2loopback" modules \
      >"$kdir/v4l2loopback/build.log" 2>&1; then
    echo "$stamp" >"$kdir/v4l2loopback/.patch"
  else
    say "v4l2loopback did not build (see $kdir/v4l2loopback/build.log): Z16 and MJPEG tests skip"
    rm -f "$loopback"
  fi
fi
expectLoopback=0
[ -s "$loopback" ] && expectLoopback=1

# ---- initramfs: busybox, the modules for 9p and vivid (with their dependencies), an init ----
initrd="$cache/initramfs"
rm -rf "$initrd" && mkdir -p "$initrd"/{bin,dev,proc,sys,host,lib/modules/"$kver"}
cp /bin/busybox "$initrd/bin/busybox"
wanted="virtio_pci 9pnet_virtio 9p vivid"
# modules.dep lists every module's dependencies transitively, in load order.
for name in $wanted; do
  grep -qE "(^|/)$name\.ko:" "$moddir/modules.dep" || fail "$kver has no module $name"
done
files=$(for name in $wanted; do grep -E "(^|/)$name\.ko:" "$moddir/modules.dep"; done |
  tr -d ':' | tr ' ' '\n' | sort -u)
for file in $files; do
  mkdir -p "$initrd/lib/modules/$kver/$(dirname "$file")"
  cp "$moddir/$file" "$initrd/lib/modules/$kver/$file"
  grep -E "^$file:" "$moddir/modules.dep" >>"$initrd/lib/modules/$kver/modules.dep"
done
[ -s "$loopback" ] && cp "$loopback" "$initrd/lib/modules/v4l2loopback.ko"
cat >"$initrd/init" <<'EOF'
#!/bin/busybox sh
/bin/busybox --install -s /bin
export PATH=/bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
uptime() { cut -d' ' -f1 /proc/uptime; }
arg() { sed -n "s/.*$1=\([^ ]*\).*/\1/p" /proc/cmdline; }
echo "v4l2-vm: booted at $(uptime) s"
for m in virtio_pci 9pnet_virtio 9p; do modprobe $m || echo "v4l2-vm: modprobe $m failed"; done
# One vivid instance with only a video capture node: /dev/video0.
modprobe vivid n_devs=1 node_types=0x1 || echo "v4l2-vm: modprobe vivid failed"
# Six loopback nodes, /dev/video1..6 (Z16, MJPG, Z16 for pairing; the virtual camera for the
# command line, for defocus ! v4l2sink, and for v4l2sink alone), 4 buffers each.
[ -e /lib/modules/v4l2loopback.ko ] && { insmod /lib/modules/v4l2loopback.ko devices=6 video_nr=1,2,3,4,5,6 \
  max_buffers=4 $(arg defocus.loopback_options) || echo "v4l2-vm: insmod v4l2loopback failed"; }
mount -t 9p -o trans=virtio,version=9p2000.L,ro,cache=loose,msize=512000 host0 /host ||
  echo "v4l2-vm: mounting the host root failed"
mount -t devtmpfs devtmpfs /host/dev
mount -t proc proc /host/proc
mount -t sysfs sysfs /host/sys
# Scratch space in the read-only host root: a tmpfs on /dev/shm, not on /tmp, so that a build
# tree under the host's /tmp (where CI may clone) stays visible to the chroot.
mkdir -p /host/dev/shm && mount -t tmpfs tmpfs /host/dev/shm
echo "v4l2-vm: drivers and host root ready at $(uptime) s"
run() { chroot /host /usr/bin/env -i PATH=/usr/bin:/bin HOME=/dev/shm TMPDIR=/dev/shm "$@"; }
run v4l2-ctl --list-devices 2>&1
echo "v4l2-vm: probe starts at $(uptime) s"
run DEFOCUS_EXPECT_LOOPBACK=$(arg defocus.loopback) "$(arg defocus.probe)" --gtest_color=no
rc=$?
echo "v4l2-vm: probe done at $(uptime) s"
cli=$(arg defocus.cli)
if [ -z "$cli" ]; then
  echo "v4l2-vm: no defocus binary given"; rc=1
else
  # The command line on vivid (reloaded: the probe unplugged it), unplugged after 2 frames:
  # exit 1 with the message, nothing under the output's name (the clip failed), and with
  # --keep-partial the frames written so far complete on disk in out.partial/.
  rmmod vivid && modprobe vivid n_devs=1 node_types=0x1
  cat >/host/dev/shm/cli.sh <<'EOS'
mkdir -p /dev/shm/out
"$1" /dev/video0 --keep-partial -o /dev/shm/out/ >/dev/shm/cli.log 2>&1 &
pid=$!
n=0
# Frames are PNGs at the top of a folder (depth/ and the TUM lists beside them); until the clip is
# done they are written into the output folder's hidden .defocus.partial/.
frames() { ls "$1"/*.png 2>/dev/null | wc -l; }
while [ "$(frames /dev/shm/out/.defocus.partial)" -lt 2 ] && [ $n -lt 1500 ]; do sleep 0.2; n=$((n + 1)); done
v4l2-ctl -d /dev/video0 -c disconnect=1
wait $pid
status=$?
tr '\r' '\n' </dev/shm/cli.log | grep -v '^frame' | grep -v ' frames, .* fps' | sed 's/^/  /'
complete=0
for f in /dev/shm/out.partial/*.png; do tail -c 12 "$f" | grep -q IEND && complete=$((complete + 1)); done
kept=$(frames /dev/shm/out.partial)
final=$(frames /dev/shm/out)
echo "  defocus exit $status; $kept frames kept in out.partial/, $complete of them complete PNGs; $final under the output's name"
[ $status = 1 ] && [ $complete -ge 2 ] && [ $complete = "$kept" ] && [ "$final" = 0 ] &&
  grep -q 'disconnected after' /dev/shm/cli.log
EOS
  run /bin/sh /dev/shm/cli.sh "$cli" || rc=1
  echo "v4l2-vm: command line done at $(uptime) s"
fi
vcam=$(arg defocus.vcam)
if [ -n "$vcam" ]; then
  # The virtual camera: defocus (and, with defocus.gst=1, gst-launch-1.0) writes a loopback node
  # while a reader captures it (scripts/v4l2-vm-vcam.sh).
  run /bin/bash "$vcam" "$(arg defocus.build)" "$(arg defocus.cache)/vcam-input" "$(arg defocus.gst)" || rc=1
  echo "v4l2-vm: virtual camera done at $(uptime) s"
fi
echo "V4L2-VM-RESULT $rc at $(uptime) s"
poweroff -f
EOF
chmod +x "$initrd/init"
(cd "$initrd" && find . | busybox cpio -o -H newc 2>/dev/null) >"$cache/initramfs.cpio"
say "prepared in $(elapsed "$start") s ($(basename "$kernel"), $(du -h "$cache/initramfs.cpio" | cut -f1) initramfs)"

# The defocus command line on vivid, unplugged mid-run, is part of every run (~40 s more, ~2 min
# under load: loading Mesa and compiling shaders under emulation).
cli=$(readlink -f "$(dirname "$probe")/../defocus")
[ -x "$cli" ] || fail "no defocus binary at $cli (build the 'defocus' target)"

# DEFOCUS_V4L2_VM_VCAM=1 also runs the virtual-camera test (scripts/v4l2-vm-vcam.sh: defocus -o
# /dev/video4 read back as a webcam); with DEFOCUS_V4L2_VM_GST=1 it also tries GStreamer's
# v4l2sink (docs/v4l2.md says how that ends). DEFOCUS_V4L2_VM_LOOPBACK="exclusive_caps=..." adds
# options to v4l2loopback.
vcam="" build=""
if [ "${DEFOCUS_V4L2_VM_VCAM:-0}" = 1 ]; then
  build=$(readlink -f "$(dirname "$probe")/..")
  for f in "$build/defocus" "$build/tests/v4l2-vcam-check"; do [ -x "$f" ] || fail "DEFOCUS_V4L2_VM_VCAM=1 but there is no $f"; done
  [ "$expectLoopback" = 1 ] || fail "DEFOCUS_V4L2_VM_VCAM=1 but v4l2loopback did not build"
  vcam="$root/scripts/v4l2-vm-vcam.sh"
  # Its input: 3 frames of the bundled clip at half size, made here (the VM sees this folder).
  [ -s "$cache/vcam-input/depth/000002.png" ] ||
    "$build/tests/v4l2-vcam-check" prepare "$root/data/tum_fr1_rpy" 3 "$cache/vcam-input" ||
    fail "could not prepare the virtual camera's input in $cache/vcam-input"
fi

# ---- the VM: software emulation (TCG; this host's nested KVM does not run the stock kernel) ----
command -v qemu-system-x86_64 >/dev/null || skip "no qemu-system-x86_64"
vmstart=$(date +%s.%N)
status=0
timeout "$([ -n "$vcam" ] && echo 1700 || echo 400)" qemu-system-x86_64 -nodefaults -no-user-config -machine pc -m 1024 -smp 1 \
  -display none -serial stdio -no-reboot \
  -kernel "$kernel" -initrd "$cache/initramfs.cpio" \
  -append "console=ttyS0 quiet panic=-1 defocus.probe=$probe defocus.loopback=$expectLoopback defocus.cli=$cli defocus.vcam=$vcam defocus.build=$build defocus.cache=$cache defocus.gst=${DEFOCUS_V4L2_VM_GST:-0} defocus.loopback_options=${DEFOCUS_V4L2_VM_LOOPBACK:-}" \
  -virtfs local,path=/,mount_tag=host0,security_model=none,readonly=on,multidevs=remap \
  </dev/null >"$cache/vm.log" 2>&1 || status=$?
tr -d '\r' <"$cache/vm.log" >"$cache/vm.txt"
sed -n '/^v4l2-vm: /,$p' "$cache/vm.txt"
result=$(sed -n 's/^V4L2-VM-RESULT \([0-9]*\).*/\1/p' "$cache/vm.txt" | tail -n 1)
say "VM ran $(elapsed "$vmstart") s, $(elapsed "$start") s in all"
if [ -z "$result" ]; then
  tail -n 40 "$cache/vm.txt"
  # qemu that cannot start (no usable accelerator, no memory) is this host's limit, not a bug.
  if ! grep -q '^v4l2-vm: booted' "$cache/vm.txt" && [ "$status" != 0 ] && [ "$status" != 124 ]; then
    skip "qemu could not run the VM (exit $status)"
  fi
  fail "the probe gave no result (qemu exit $status; log: $cache/vm.txt)"
fi
[ "$result" = 0 ] || fail "the probe or the command line failed in the VM (exit $result)"
# Without the loopback module the probe's Z16, MJPEG and pairing tests did not run: what passed
# is only part of the test, so it reports skipped, not passed.
[ "$expectLoopback" = 1 ] || skip "vivid and the command line passed, but v4l2loopback did not build (see $kdir/v4l2loopback/build.log): the Z16, MJPEG and pairing tests did not run"
say "PASS"
