#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# The Debian package (cpack -G DEB, cmake/Package.cmake) holds what a cluster admin needs on a
# node: defocus and the other programs, libdefocus, the GStreamer plugin, the Slurm and GNU
# parallel scripts; declares the Debian packages of the libraries it links (dpkg-shlibdeps); and
# its defocus runs from the unpacked files. Defects caught: a package without the programs or the
# scripts, one with test binaries, one that declares no dependencies (installs, then fails to
# start on a node without OpenCV), one whose programs find no libdefocus.
#   tests/package-test.sh BUILD_DIR DEFOCUS_CLI           (CTest: package, label install)
set -euo pipefail
build=$1 cli=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "package-test: $*"; exit 1; }
command -v dpkg-deb >/dev/null || { echo "package-test: SKIPPED: no dpkg-deb"; exit 77; }

(cd "$work" && cpack -G DEB -B "$work" --config "$build/CPackConfig.cmake" >"$work/cpack.log" 2>&1) ||
  { cat "$work/cpack.log"; fail "cpack -G DEB failed"; }
deb=$(find "$work" -maxdepth 1 -name 'defocus_*.deb')
[ -n "$deb" ] || fail "cpack made no defocus_*.deb"
dpkg-deb -c "$deb" | awk '{print $NF}' >"$work/contents"
prefix=$(sed -n 's|^\./\(.*\)/bin/defocus$|/\1|p' "$work/contents")
[ -n "$prefix" ] || fail "$(basename "$deb") has no bin/defocus"
for path in bin/defocus bin/defocus-preview bin/defocus-synthetic bin/defocus-bench \
            share/defocus/defocus.sbatch share/defocus/batch-parallel.sh include/defocus/defocus.hpp; do
  grep -qx "\./${prefix#/}/$path" "$work/contents" || fail "$(basename "$deb") has no $prefix/$path"
done
grep -q '/libdefocus\.so\.' "$work/contents" || fail "$(basename "$deb") has no libdefocus.so"
! grep -qE '(Test|-probe|defocus-soak)$' "$work/contents" || fail "$(basename "$deb") holds test programs"
depends=$(dpkg-deb -f "$deb" Depends)
for needed in libopencv-core libegl1 libstdc++6; do
  grep -q "$needed" <<<"$depends" || fail "Depends does not name $needed: '$depends'"
done

# The unpacked defocus finds the package's libdefocus by its RPATH.
dpkg-deb -x "$deb" "$work/root"
version=$(env -u LD_LIBRARY_PATH "$work/root$prefix/bin/defocus" --version) || fail "the packaged defocus does not start"
[ "$version" = "$("$cli" --version)" ] || fail "the packaged defocus --version says '$version'"
echo "package-test: $(basename "$deb") for $prefix: $version, the programs, scripts, library and headers; Depends: $depends"
