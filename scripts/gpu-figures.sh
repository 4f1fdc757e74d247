#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# The GPU figures of docs/benchmarks.md in one command on a machine with an NVIDIA GPU and none
# of the project's packages (such as the lent H100/H200), from a bundle packed here.
#   scripts/gpu-figures.sh pack [BUILD_DIR [OLD_BUILD_DIR]]
#                                             here: defocus and defocus-bench with the libraries
#                                             they load into .gpu/ (ignored by git: carry it);
#                                             with OLD_BUILD_DIR (another checkout's build) also
#                                             that build's, for run's old/new rounds
#   scripts/gpu-figures.sh run [OUT_DIR]      there, from a copy of the repository root: the GPU
#                                             and driver, frames in flight against one at a time,
#                                             and the per-pass table, into OUT_DIR ($OUT or out/gpu);
#                                             40 frames per size (640x480 to 4K) and way, 3 passes;
#                                             with an old build packed, first the new and the old
#                                             build's throughput and per-stage rows, alternating,
#                                             three rounds (versus.txt)
# DEFOCUS_GPU_STEPS=a,b,... runs only those steps of run (info and machine.txt always): versus,
# throughput, passes, yield, passes-finished, prep, compute, frames, aperture-bench, apertures,
# read, i420, yuyv, write.
# On the lent machine, whose $OUT brings back only a few files, run into a temporary folder and
# tar it into $OUT.
# pack needs the bundler of ../shared/tools/gpu (or DEFOCUS_GPU_TOOLS=DIR): it is the project's
# tool for that machine, not part of the build. run prints each step's command before its output.
# Exit: 0 done, 1 a step failed (the files so far are kept), 2 usage.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
case ${1:-} in
  pack)
    build=${2:-build}
    tools=${DEFOCUS_GPU_TOOLS:-$root/../shared/tools/gpu}
    if [[ ! -f $tools/bundle.py ]]; then
      echo "gpu-figures: error: no bundler at $tools/bundle.py (set DEFOCUS_GPU_TOOLS)" >&2; exit 1
    fi
    for program in defocus defocus-bench; do
      [[ -x $build/$program ]] || { echo "gpu-figures: error: $build/$program is not built" >&2; exit 1; }
    done
    staging=$(mktemp -d)
    trap 'rm -rf "$staging"' EXIT
    python3 "$tools/bundle.py" "$build" "$staging/bundle" defocus defocus-bench
    mkdir -p .gpu
    tar -C "$staging/bundle" -cJf .gpu/bundle.tar.xz bin lib
    cp "$tools/env.sh" .gpu/env.sh
    git rev-parse --short HEAD > .gpu/commit 2>/dev/null || echo unknown > .gpu/commit
    rm -f .gpu/versus.tar.xz .gpu/versus-commit
    if [[ -n ${3:-} ]]; then
      old=$3
      for program in defocus defocus-bench; do
        [[ -x $old/$program ]] || { echo "gpu-figures: error: $old/$program is not built" >&2; exit 1; }
      done
      python3 "$tools/bundle.py" "$old" "$staging/versus" defocus defocus-bench
      tar -C "$staging/versus" -cJf .gpu/versus.tar.xz bin lib
      source_dir=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$old/CMakeCache.txt")
      git -C "$source_dir" rev-parse --short HEAD > .gpu/versus-commit 2>/dev/null || echo unknown > .gpu/versus-commit
      echo "gpu-figures: the old build of $(cat .gpu/versus-commit) packed beside it"
    fi
    echo "gpu-figures: .gpu/ packed ($(du -h .gpu/bundle.tar.xz | cut -f1)) from $(cat .gpu/commit); run there:" \
         "scripts/gpu-figures.sh run, carrying .gpu"
    ;;
  run)
    out=${2:-${OUT:-out/gpu}}
    # Smaller for a try on llvmpipe: DEFOCUS_GPU_SIZES=320x240 DEFOCUS_GPU_FRAMES=6
    sizes=${DEFOCUS_GPU_SIZES:-640x480,1920x1080,3840x2160}
    frames=${DEFOCUS_GPU_FRAMES:-40}
    [[ -f .gpu/bundle.tar.xz ]] || { echo "gpu-figures: error: no .gpu/bundle.tar.xz (pack it first)" >&2; exit 1; }
    mkdir -p "$out"
    unpacked=$(mktemp -d)
    tar -C "$unpacked" -xJf .gpu/bundle.tar.xz
    # NVIDIA's EGL and the bundle's libraries (env.sh's probes may fail where a path is absent).
    set +eu +o pipefail
    # shellcheck disable=SC1091
    . .gpu/env.sh "$unpacked"
    set -euo pipefail
    step() {
      local name=$1; shift
      echo "\$ $*" | tee "$out/$name.txt"
      "$@" 2>&1 | tee -a "$out/$name.txt"
    }
    wanted() { [[ ,${DEFOCUS_GPU_STEPS:-all}, == *,all,* || ,${DEFOCUS_GPU_STEPS:-}, == *,$1,* ]]; }
    { date -u +%FT%TZ; cat .gpu/commit; nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null || true; } \
      | tee "$out/machine.txt"
    step info "$unpacked/bin/defocus" --info
    if [[ -f .gpu/versus.tar.xz ]] && wanted versus; then
      # The build before a change and the build after, alternating, so that the machine's drift
      # falls on both: frames in flight and one at a time, then each stage's row.
      old=$(mktemp -d)
      tar -C "$old" -xJf .gpu/versus.tar.xz
      echo "new: $(cat .gpu/commit), old: $(cat .gpu/versus-commit)" > "$out/versus.txt"
      for round in 1 2 3; do
        for build in new old; do
          bin=$unpacked/bin
          [[ $build == old ]] && bin=$old/bin
          for command in "throughput --sizes $sizes --frames $frames --passes 1" \
                         "--sizes ${sizes#*,} --runs $frames --warmup 5"; do
            echo "\$ [$build, round $round] defocus-bench $command" | tee -a "$out/versus.txt"
            # shellcheck disable=SC2086
            LD_LIBRARY_PATH=${bin%/bin}/lib:$LD_LIBRARY_PATH "$bin/defocus-bench" $command 2>&1 | tee -a "$out/versus.txt"
          done
        done
      done
    fi
    if wanted throughput; then
      step throughput "$unpacked/bin/defocus-bench" throughput --sizes "$sizes" --frames "$frames" --passes 3
    fi
    if wanted passes; then
      step passes "$unpacked/bin/defocus-bench" --sizes "$sizes" --runs "$frames" --warmup 5 --json "$out/bench.json"
    fi
    if wanted yield; then
      # The per-stage rows with NVIDIA's driver sleeping in its waits instead of yielding in a
      # loop (__GL_YIELD=USLEEP), beside the default: how much of the calling thread's CPU row
      # ("of which in fence waits") is spinning, and what sleeping costs the wall time.
      for round in 1 2; do
        step "yield-default-$round" "$unpacked/bin/defocus-bench" --sizes "${sizes#*,}" --runs "$frames" --warmup 5
        step "yield-usleep-$round" env __GL_YIELD=USLEEP "$unpacked/bin/defocus-bench" --sizes "${sizes#*,}" \
          --runs "$frames" --warmup 5
      done
    fi
    if wanted passes-finished; then
      # Each pass's wall time with the GPU idle before it: a timer query's scope also holds what
      # the pass waited for (the frame's transfer to the GPU, for the first passes to read it).
      step passes-finished "$unpacked/bin/defocus-bench" --sizes "${sizes#*,}" --runs "$frames" --warmup 5 \
        --finish-each-pass
    fi
    if wanted prep; then
      # Depth prep and the scene measurement on the GPU against the CPU's, frames alternating.
      step prep "$unpacked/bin/defocus-bench" --sizes "$sizes" --runs "$frames" --warmup 5 --versus-cpu-prep \
        --json "$out/bench-prep.json"
    fi
    if wanted compute; then
      # The passes as compute shaders against the same shaders drawn, frames alternating, and the
      # frames out of both (one 1080p frame per preset, and their largest difference).
      step compute "$unpacked/bin/defocus-bench" --sizes "$sizes" --runs "$frames" --warmup 5 --versus-fragment \
        --json "$out/bench-compute.json"
    fi
    if wanted frames; then
      for preset in fast balanced high; do
        for stage in compute fragment; do
          DEFOCUS_PASSES=$stage "$unpacked/bin/defocus" data/tum_fr1_rpy --focus 1.0 --f-number 1.4 --frames 1 \
            --quality "$preset" -y -o "$out/frame-$preset-$stage.exr" > /dev/null 2>&1 || true
        done
      done
    fi
    if wanted aperture-bench; then
      # The apertures beside the hexagon on the bundled clip, each stage's row, alternating, two
      # rounds (the clip has no light above white: the gather's cost, not the sprites').
      for round in 1 2; do
        for aperture in "--blades 6" "--blades 0" "--blades 9" "--blades 7 --blade-rotation 15" \
                        "--blades 0 --aperture-ratio 2"; do
          # shellcheck disable=SC2086 # $aperture is a list of options
          step "aperture-bench-$round-${aperture//[^0-9a-z]/}" "$unpacked/bin/defocus-bench" --sizes "${sizes#*,}" \
            --runs "$frames" --warmup 5 $aperture
        done
      done
    fi
    if wanted apertures; then
      # The apertures beside the hexagon on a corpus scene whose lights are above white (needs
      # python3-opencv there to make the frames).
      for size in 1920x1080 3840x2160; do
        step "apertures-$size" scripts/aperture-cost.sh "$unpacked/bin" data/corpus/spheres-far-focus "$size" 20 3 ||
          echo "gpu-figures: apertures at $size not measured (see $out/apertures-$size.txt)"
      done
    fi
    if wanted read; then
      # Reading a 1080p clip ahead of the filter on 1 to 8 threads, and the command line's wall time
      # with one reading thread and with its default (needs python3-opencv there to make the frames).
      step read scripts/read-cost.sh "$unpacked/bin" 1920x1080 48 1,2,4,8 ||
        echo "gpu-figures: reading not measured (see $out/read.txt)"
    fi
    if wanted i420; then
      # Colour as I420 planes (uploaded as they came, converted on the GPU) against BGR, in flight.
      step i420 "$unpacked/bin/defocus-bench" throughput --versus-i420 --sizes "$sizes" --frames "$frames" --passes 3 ||
        echo "gpu-figures: I420 not measured (see $out/i420.txt)"
    fi
    if wanted yuyv; then
      # A webcam's YUYV the same way.
      step yuyv "$unpacked/bin/defocus-bench" throughput --versus-yuv yuyv --sizes "$sizes" --frames "$frames" --passes 3 ||
        echo "gpu-figures: YUYV not measured (see $out/yuyv.txt)"
    fi
    if wanted write; then
      # Writing a 1080p folder output behind the filter on 1 to 8 encoding threads.
      step write "$unpacked/bin/defocus-bench" write --size 1920x1080 --frames 48 --threads 1,2,4,8 --passes 3 ||
        echo "gpu-figures: writing not measured (see $out/write.txt)"
    fi
    files=("$out"/*)
    echo "gpu-figures: done; $out holds ${files[*]##*/}"
    ;;
  *)
    echo "usage: scripts/gpu-figures.sh pack [BUILD_DIR [OLD_BUILD_DIR]] | run [OUT_DIR]" >&2
    exit 2
    ;;
esac
