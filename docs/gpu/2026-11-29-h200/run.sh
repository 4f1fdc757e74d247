#!/usr/bin/env bash
# One device session's measurements (not in git): machine, corpus accuracy, throughput, passes, Y'CbCr.
set -u
out=${OUT:-out/gpu}; mkdir -p "$out"
u=$(mktemp -d); tar -C "$u" -xJf .gpu/bundle.tar.xz
set +eu; . .gpu/env.sh "$u"; set -u
B=$u/bin
start=$(date +%s)
{ date -u +%FT%TZ; cat .gpu/commit; nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc; } > "$out/machine.txt" 2>&1
t() { local n=$1 lim=$2; shift 2; echo "\$ $*" > "$out/$n.txt"; echo "[$n at $(( $(date +%s) - start )) s]"; timeout "$lim" "$@" >> "$out/$n.txt" 2>&1; echo "exit $? after $(( $(date +%s) - start )) s" >> "$out/$n.txt"; }
t info 60 "$B/defocus" --info
t accuracy 120 "$B/defocus-bench-accuracy" --scene data/blender_spheres --scene data/corpus --presets fast,balanced,high -o "$out/acc"
t apertures 120 "$B/defocus-bench-accuracy" --scene data/corpus-apertures --presets fast,balanced,high -o "$out/acc-ap"
t throughput 120 "$B/defocus-bench" throughput --sizes 640x480,1920x1080,3840x2160 --frames 40 --passes 3
t passes-balanced 90 "$B/defocus-bench" --sizes 1920x1080,3840x2160 --runs 30 --warmup 5 --json "$out/bench-balanced.json"
t passes-high 90 "$B/defocus-bench" --quality high --sizes 1920x1080,3840x2160 --runs 30 --warmup 5 --json "$out/bench-high.json"
t yuyv 60 "$B/defocus-bench" throughput --versus-yuv yuyv --sizes 1920x1080,3840x2160 --frames 40 --passes 3
t i420 60 "$B/defocus-bench" throughput --versus-yuv i420 --sizes 1920x1080,3840x2160 --frames 40 --passes 3
echo "done after $(( $(date +%s) - start )) s"
