#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Builds the Containerfile with podman and checks the image: defocus runs in it (--version, --info
# on Mesa's llvmpipe, two frames of the bundled clip through --batch, a report written), and the
# final stage holds no compiler (no gcc, g++, cc, c++) and no -dev package.
#   scripts/container-test.sh           (CTest: ctest -L container; slow: 21 min on 2 busy cores
#                                        with podman's layer cache warm, more on a fresh machine)
# Exit: 0 passed, 1 failed, 77 skipped, with the reason: not root (rootful podman), podman, runc
# or debootstrap missing and not installable, or no network to the Debian mirror that the image's
# apt-get needs. podman, runc and debootstrap are installed when missing.
# Without a `debian:12` image and with no registry to pull from, it makes one with debootstrap
# from the Debian mirror this machine's apt uses (a minbase bookworm, imported as
# localhost/debian:12). podman runs with runc, host networking and explicit ulimits, which works
# where crun refuses hybrid cgroups and raising RLIMIT_NPROC (as in this project's VM). Dangling
# images of earlier runs are pruned; this run's layers stay as the next run's cache.
set -u
root=$(cd "$(dirname "$0")/.." && pwd)
say() { echo "container-test: $*"; }
skip() { say "SKIPPED: $*"; exit 77; }
fail() { say "FAILED: $*"; exit 1; }
[ "$(id -u)" -eq 0 ] || skip "run as root (rootful podman)"

# ---- packages, installed only when missing (the pattern of scripts/setup.sh) ----
packages=(podman runc debootstrap)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  say "installing ${missing[*]}"
  log=$(mktemp)
  { apt-get update -q && DEBIAN_FRONTEND=noninteractive \
      apt-get install -y -q --no-install-recommends "${missing[@]}"; } >"$log" 2>&1 ||
    skip "could not install ${missing[*]} (see $log)"
fi

# ---- the Debian mirror: the one apt uses here, reachable, or the image cannot install a thing ----
mirror=$(apt-get --print-uris download base-files 2>/dev/null | sed -n "s|^'\(.*\)/pool/.*|\1|p" | head -n 1)
[ -n "$mirror" ] || skip "apt names no Debian mirror here"
hostport=${mirror#*://}; hostport=${hostport%%/*}
host=${hostport%%:*}; port=80
[ "$hostport" != "$host" ] && port=${hostport#*:}
case $mirror in https://*) [ "$hostport" = "$host" ] && port=443 ;; esac
timeout 20 bash -c "exec 3<>/dev/tcp/$host/$port" 2>/dev/null || skip "no network to the Debian mirror $mirror"

work=$(mktemp -d /tmp/defocus-container.XXXXXX)
trap 'rm -rf "$work"' EXIT
started=$(date -u +%Y-%m-%dT%H:%M:%SZ)
run_opts=(--ulimit nproc=1000:1000 --ulimit nofile=1024:1024 --network host)
pod=(podman --runtime runc)

if ! "${pod[@]}" image exists debian:12 && ! "${pod[@]}" image exists localhost/debian:12; then
  say "making debian:12 with debootstrap from $mirror"
  mkdir "$work/rootfs"
  debootstrap --variant=minbase bookworm "$work/rootfs" "$mirror" >"$work/debootstrap.log" 2>&1 ||
    { tail -n 5 "$work/debootstrap.log"; fail "debootstrap failed with the mirror reachable"; }
  rm -rf "$work"/rootfs/var/cache/apt/archives/*.deb
  tar -C "$work/rootfs" -c . | "${pod[@]}" import - localhost/debian:12 >/dev/null || fail "podman import failed"
  rm -rf "$work/rootfs"
fi

say "building (podman build -f Containerfile)"
image=localhost/defocus:test
"${pod[@]}" build "${run_opts[@]}" -f "$root/Containerfile" -t "$image" "$root" >"$work/build.log" 2>&1 ||
  { tail -n 30 "$work/build.log"; fail "the build failed"; }
run() { "${pod[@]}" run --rm "${run_opts[@]}" "$@"; }
run "$image" --version || fail "defocus --version failed in the image"
run "$image" --info | grep -q "llvmpipe" || fail "defocus --info shows no llvmpipe in the image"
compilers=$(run --entrypoint sh "$image" -c 'command -v gcc g++ cc c++ clang; dpkg -l | awk "/^ii/ && \$2 ~ /-dev(:|$)/ { print \$2 }"')
[ -z "$compilers" ] || fail "the image has build tools: $compilers"
mkdir "$work/clips"
cp -r "$root/data/tum_fr1_rpy" "$work/clips/"
printf 'tum_fr1_rpy\t-\tout/clip/\t--frames 2 --focus 1.0 --quality fast\n' > "$work/clips/clips.tsv"
run -v "$work/clips:/work" -w /work "$image" --batch clips.tsv || fail "defocus --batch failed in the image"
[ "$(find "$work/clips/out/clip" -maxdepth 1 -name '[!.]*.png' | wc -l)" -eq 2 ] || fail "the batch in the image wrote no 2 frames"
grep -q '"status": "done"' "$work/clips/out/clip.report.json" || fail "no done report from the image"
size=$("${pod[@]}" image inspect "$image" --format '{{.Size}}')
# Earlier runs' dangling images (a build stage is about 2 GB); this run's stay as the cache.
"${pod[@]}" image prune -f --filter "until=$started" >/dev/null 2>&1 || true
say "image $image, $((size / 1000000)) MB: defocus runs, no compiler, --batch wrote 2 frames and a report"
echo "1 passed, 0 failed"
