#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Installs defocus into a temporary prefix, builds tests/consumer against it twice (CMake package,
# then pkg-config) and checks that each consumer's PNG of one bundled frame is the same file, byte
# for byte, as the command line's with the same settings; that the GStreamer plugin is installed
# where GStreamer finds it, loading the installed library; and that the programs users run and the
# batch scripts are installed (bin/, share/defocus/), the test and measuring tools not, and the
# installed defocus runs on the installed library. Defects caught: a program or script the docs
# point at that `cmake --install` leaves out, an installed program that finds no libdefocus (no
# RPATH to the prefix's) or loads the build tree's, a test binary shipped to users.
#   tests/install-test.sh BUILD_DIR DEFOCUS_CLI [PRESET]        (CTest: install_PRESET, label install)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$1 cli=$2 preset=${3:-balanced}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --install "$build" --prefix "$work/prefix" >/dev/null

# The programs and scripts, and nothing of the tests.
prefix=$work/prefix
for program in defocus defocus-preview defocus-synthetic defocus-bench; do
  [ -x "$prefix/bin/$program" ] || { echo "install-test: $program is not installed in $prefix/bin"; exit 1; }
  env -u LD_LIBRARY_PATH "$prefix/bin/$program" --help >/dev/null ||
    { echo "install-test: the installed $program --help fails"; exit 1; }
done
for script in defocus.sbatch batch-parallel.sh; do
  [ -x "$prefix/share/defocus/$script" ] || { echo "install-test: $script is not installed in $prefix/share/defocus"; exit 1; }
done
extra=$(find "$prefix/bin" -type f \( -name '*Test' -o -name '*-probe' -o -name 'defocus-soak' -o -name 'v4l2-*' \))
[ -z "$extra" ] || { echo "install-test: test programs installed: $extra"; exit 1; }
lib=$(env -u LD_LIBRARY_PATH ldd "$prefix/bin/defocus" | awk '/libdefocus/ {print $3}')
case "$lib" in "$prefix/"*) ;; *) echo "install-test: the installed defocus loads '$lib', not the installed library"; exit 1 ;; esac
version=$(env -u LD_LIBRARY_PATH "$prefix/bin/defocus" --version)
[ "$version" = "$("$cli" --version)" ] || { echo "install-test: the installed defocus --version says '$version'"; exit 1; }
echo "install-test: $version and the other programs in bin/, the batch scripts in share/defocus/, no test programs"
# Frame 9 of the bundled clip (the README's picture) and its associated depth.
read -r _ rgb _ depth < <(sed -n 9p "$root/data/tum_fr1_rpy/associations.txt")
color=$root/data/tum_fr1_rpy/$rgb depth=$root/data/tum_fr1_rpy/$depth

"$cli" "$color" --depth "$depth" --depth-scale 5000 --focus 1.0 --f-number 1.4 --quality "$preset" \
  -o "$work/cli.png" -q >/dev/null

status=0
for mode in cmake pkg-config; do
  flags=(-DCMAKE_PREFIX_PATH="$work/prefix")
  [ "$mode" = pkg-config ] && flags=(-DUSE_PKG_CONFIG=ON)
  PKG_CONFIG_PATH="$(dirname "$(find "$work/prefix" -name defocus.pc)")" \
    cmake -S "$root/tests/consumer" -B "$work/build-$mode" -G Ninja -DCMAKE_BUILD_TYPE=Release "${flags[@]}" >/dev/null
  cmake --build "$work/build-$mode" >/dev/null
  # The installed library must be the one loaded, not the build tree's.
  lib=$(ldd "$work/build-$mode/defocus-consumer" | awk '/libdefocus/ {print $3}')
  case "$lib" in "$work/prefix/"*) ;; *) echo "install-test: $mode consumer loads '$lib', not the installed library"; exit 1 ;; esac
  "$work/build-$mode/defocus-consumer" "$color" "$depth" 5000 1.0 1.4 "$preset" "$work/$mode.png"
  if cmp -s "$work/cli.png" "$work/$mode.png"; then
    echo "install-test: $mode consumer ($preset) = defocus CLI, byte for byte"
  else
    echo "install-test: $mode consumer ($preset) differs from the defocus CLI"
    status=1
  fi
done

# The GStreamer plugin (when the build has it): installed in LIBDIR/gstreamer-1.0 beside the
# library, loading the installed libdefocus, and found there by GStreamer with both its elements.
if [ -e "$build/gst/libgstdefocus.so" ]; then
  plugin=$(find "$work/prefix" -name libgstdefocus.so)
  library=$(find "$work/prefix" -name 'libdefocus.so.*' | head -n 1)
  if [ -z "$plugin" ] || [ "$(dirname "$plugin")" != "$(dirname "$library")/gstreamer-1.0" ]; then
    echo "install-test: libgstdefocus.so is at '$plugin', not in $(dirname "$library")/gstreamer-1.0"
    exit 1
  fi
  lib=$(ldd "$plugin" | awk '/libdefocus/ {print $3}')
  case "$lib" in "$work/prefix/"*) ;; *) echo "install-test: the installed plugin loads '$lib', not the installed library"; exit 1 ;; esac
  for element in defocus defocussrc; do
    GST_PLUGIN_PATH="$(dirname "$plugin")" GST_REGISTRY="$work/registry.bin" gst-inspect-1.0 "$element" \
      >"$work/inspect.txt" 2>&1 || { echo "install-test: GStreamer does not find $element in the install"; exit 1; }
    grep -q "Filename *$plugin" "$work/inspect.txt" || { echo "install-test: $element is not loaded from $plugin"; exit 1; }
  done
  echo "install-test: the GStreamer plugin is in $(dirname "$plugin") and GStreamer finds defocus and defocussrc there"
fi
exit $status
