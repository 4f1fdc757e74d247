#!/usr/bin/env bash
# Builds the Containerfile with podman and checks the image: defocus runs in it (--version, --info
# on Mesa's llvmpipe, two frames of the bundled clip through --batch, a report written), and the
# final stage holds no compiler (no gcc, g++, cc, c++) and no -dev package.
#   scripts/container-test.sh           (not part of ctest: it downloads Debian packages and
#                                        takes 15-30 min on 2 cores; exit 77 = cannot run here)
# Without a `debian:12` image and with no registry to pull from, it makes one with debootstrap
# from the Debian mirror apt uses (a minbase bookworm, imported as localhost/debian:12).
# podman runs with runc, host networking and explicit ulimits, which works where crun refuses
# hybrid cgroups and raising RLIMIT_NPROC (as in this project's VM).
set -u
root=$(cd "$(dirname "$0")/.." && pwd)
skip() { echo "container-test: SKIPPED: $*"; exit 77; }
fail() { echo "container-test: FAILED: $*"; exit 1; }
command -v podman >/dev/null || skip "podman is not installed (apt-get install podman runc)"
[ "$(id -u)" -eq 0 ] || skip "run as root (rootful podman)"
run_opts=(--ulimit nproc=1000:1000 --ulimit nofile=1024:1024 --network host)
pod=(podman)
command -v runc >/dev/null && pod+=(--runtime runc)

if ! "${pod[@]}" image exists debian:12 && ! "${pod[@]}" image exists localhost/debian:12; then
  command -v debootstrap >/dev/null || skip "no debian:12 image and no debootstrap to make one"
  rootfs=$(mktemp -d /tmp/defocus-rootfs.XXXXXX)
  trap 'rm -rf "$rootfs"' EXIT
  echo "container-test: making debian:12 with debootstrap"
  debootstrap --variant=minbase bookworm "$rootfs" http://deb.debian.org/debian >/dev/null ||
    skip "debootstrap failed (no Debian mirror?)"
  rm -rf "$rootfs"/var/cache/apt/archives/*.deb
  tar -C "$rootfs" -c . | "${pod[@]}" import - localhost/debian:12 >/dev/null || fail "podman import failed"
fi

echo "container-test: building (podman build -f Containerfile)"
"${pod[@]}" build "${run_opts[@]}" -f "$root/Containerfile" -t localhost/defocus:test "$root" \
  > /tmp/defocus-container-build.log 2>&1 || { tail -n 30 /tmp/defocus-container-build.log; fail "the build failed"; }
image=localhost/defocus:test
run() { "${pod[@]}" run --rm "${run_opts[@]}" "$@"; }
run "$image" --version || fail "defocus --version failed in the image"
run "$image" --info | grep -q "llvmpipe" || fail "defocus --info shows no llvmpipe in the image"
compilers=$(run --entrypoint sh "$image" -c 'command -v gcc g++ cc c++ clang; dpkg -l | awk "/^ii/ && \$2 ~ /-dev(:|$)/ { print \$2 }"')
[ -z "$compilers" ] || fail "the image has build tools: $compilers"
work=$(mktemp -d /tmp/defocus-container.XXXXXX)
cp -r "$root/data/tum_fr1_rpy" "$work/"
printf 'tum_fr1_rpy\t-\tout/clip/\t--frames 2 --focus 1.0 --quality fast\n' > "$work/clips.tsv"
run -v "$work:/work" -w /work "$image" --batch clips.tsv || fail "defocus --batch failed in the image"
[ "$(find "$work/out/clip" -maxdepth 1 -name '[!.]*.png' | wc -l)" -eq 2 ] || fail "the batch in the image wrote no 2 frames"
grep -q '"status": "done"' "$work/out/clip.report.json" || fail "no done report from the image"
size=$("${pod[@]}" image inspect "$image" --format '{{.Size}}')
rm -rf "$work"
echo "container-test: image $image, $((size / 1000000)) MB: defocus runs, no compiler, --batch wrote 2 frames and a report"
echo "1 passed, 0 failed"
