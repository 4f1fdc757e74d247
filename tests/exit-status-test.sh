#!/bin/sh
# SPDX-License-Identifier: LGPL-2.1-or-later
# Every defocus program's exit status for each kind of ending (samples/ExitStatus.hpp, README
# "Exit status"): 0 done, 1 bad input or output, 2 command line, 75 no GL (retry), 130 Ctrl-C,
# 143 SIGTERM; errors on standard error, one line, standard output left to results.
# Defects caught: CLI11's own codes (105-109) for parse errors, a missing GL context reported as
# bad input (a batch runner would not retry it), SIGTERM reported as Ctrl-C, an existing output
# overwritten without -y, diagnostics on standard output.
#   tests/exit-status-test.sh BUILD_DIR DATA_DIR
set -u
build=$1
data=$2
scratch=$build/test-scratch/exit-status
rm -rf "$scratch" && mkdir -p "$scratch"
failures=0

# expect STATUS NAME COMMAND...: runs COMMAND, compares its status, keeps stdout and stderr.
expect() {
    want=$1 name=$2
    shift 2
    "$@" >"$scratch/out" 2>"$scratch/err"
    got=$?
    if [ "$got" -ne "$want" ]; then
        echo "FAIL $name: exit $got, expected $want: $*"
        sed 's/^/  stderr: /' "$scratch/err" | head -5
        failures=$((failures + 1))
    else
        echo "ok   $name: exit $got"
    fi
}

# stderr_one_line NAME: the last run said why in one line on stderr and nothing on stdout.
stderr_one_line() {
    lines=$(grep -c 'error' "$scratch/err")
    if [ "$lines" -ne 1 ] || [ -s "$scratch/out" ]; then
        echo "FAIL $1: expected one error line on stderr and an empty stdout"
        sed 's/^/  stderr: /' "$scratch/err" | head -5
        sed 's/^/  stdout: /' "$scratch/out" | head -5
        failures=$((failures + 1))
    fi
}

no_gl() { __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent "$@"; }

for program in defocus defocus-preview defocus-bench defocus-soak defocus-synthetic defocus-bench-accuracy; do
    expect 0 "$program --help" "$build/$program" --help
    expect 2 "$program unknown option" "$build/$program" --no-such-option
    stderr_one_line "$program unknown option"
done
expect 2 "defocus value out of range" "$build/defocus" "$data" -o "$scratch/x.mp4" --f-number 0.1
stderr_one_line "defocus value out of range"
# A range said as a user would write it, in every program. Defect: CLI11's "Value 0 not in range
# 0.000000 to 17976931348623157081..." (389 characters for an open end).
range_message() {
    message=$1 label=$2
    shift 2
    expect 2 "$label" "$@"
    stderr_one_line "$label"
    if ! grep -q -- "$message" "$scratch/err" || [ "$(wc -c <"$scratch/err")" -gt 160 ]; then
        echo "FAIL $label: expected \"$message\" in a short line"
        sed 's/^/  stderr: /' "$scratch/err" | cut -c1-200
        failures=$((failures + 1))
    fi
}
range_message "error: --f-number must be between 0.7 and 64, not 0.1" "defocus --f-number range message" \
    "$build/defocus" "$data" -o "$scratch/x.mp4" --f-number 0.1
range_message "error: --frames must be at least 1, not 0 (see --help)" "defocus --frames range message" \
    "$build/defocus" "$data" -o "$scratch/x.mp4" --frames 0
range_message "error: --in-flight must be between 1 and 16, not 17 (see --help)" "defocus --in-flight range message" \
    "$build/defocus" --batch "$scratch/m.tsv" --in-flight 17
range_message "error: --fps must be more than 0, not 0 (see --help)" "defocus --fps range message" \
    "$build/defocus" "$data" -o "$scratch/x.mp4" --fps 0
range_message "error: --frames must be at least 1, not 0 (see --help)" "defocus-preview range message" \
    "$build/defocus-preview" "$data" --frames 0
range_message "error: --runs must be between 3 and 10000, not 1 (see --help)" "defocus-bench range message" \
    "$build/defocus-bench" timing --runs 1
range_message "error: --width must be between 2 and 8192, not 1 (see --help)" "defocus-soak range message" \
    "$build/defocus-soak" --width 1
range_message "error: --runs must be between 1 and 100, not 0 (see --help)" "defocus-synthetic range message" \
    "$build/defocus-synthetic" --runs 0
range_message "error: --runs must be between 5 and 1000, not 1 (see --help)" "defocus-bench-accuracy range message" \
    "$build/defocus-bench-accuracy" --runs 1
expect 2 "defocus-preview bad value" "$build/defocus-preview" "$data" --f-number abc
expect 2 "defocus-bench subcommand option" "$build/defocus-bench" timing --no-such-option
expect 0 "defocus-bench subcommand help" "$build/defocus-bench" plan --help
grep -q -- '--passes' "$scratch/out" || { echo "FAIL defocus-bench plan --help lacks its options"; failures=$((failures + 1)); }

# 1: input or output that cannot work.
expect 1 "defocus missing input" "$build/defocus" "$scratch/missing" -o "$scratch/x.mp4"
stderr_one_line "defocus missing input"
expect 1 "defocus-preview missing input" "$build/defocus-preview" "$scratch/missing" --no-window
expect 1 "defocus-bench missing data" "$build/defocus-bench" --data "$scratch/missing" --runs 1 --warmup 0
expect 1 "defocus-bench-accuracy missing data" "$build/defocus-bench-accuracy" --data "$scratch/missing" -o "$scratch/acc"
: >"$scratch/exists.mp4"
expect 1 "defocus existing output without -y" "$build/defocus" "$data" -o "$scratch/exists.mp4" --frames 1
stderr_one_line "defocus existing output without -y"
[ -s "$scratch/exists.mp4" ] && { echo "FAIL the refused output was written"; failures=$((failures + 1)); }
expect 0 "defocus existing output with -y" "$build/defocus" "$data" -o "$scratch/exists.mp4" --frames 1 -y -q
[ -s "$scratch/exists.mp4" ] || { echo "FAIL -y did not replace the output"; failures=$((failures + 1)); }

# Requests that can never be met are refused in one line, with 2 when the command line alone says
# so and 1 when the input has to be read first. Defects: --egl-device beyond the machine's devices
# exiting 75 (a batch runner would retry a job that can never run) with a C++ name in the message;
# --focus-point outside the frame accepted; FFmpeg's own "[mp4 @ 0x...]" line before ours.
expect 2 "defocus --egl-device beyond the machine's" "$build/defocus" "$data" -o "$scratch/dev.mp4" --egl-device 99
stderr_one_line "defocus --egl-device beyond the machine's"
grep -q -- '--egl-device 99 does not exist here' "$scratch/err" || { echo "FAIL --egl-device message"; failures=$((failures + 1)); }
grep -q '::' "$scratch/err" && { echo "FAIL --egl-device message names C++ code"; failures=$((failures + 1)); }
expect 1 "defocus --focus-point outside the frame" "$build/defocus" "$data" -o "$scratch/point/" --focus-point 9999,9999
stderr_one_line "defocus --focus-point outside the frame"
grep -q -- '--focus-point 9999,9999 is outside the 640x480 frame' "$scratch/err" || {
    echo "FAIL --focus-point message"; failures=$((failures + 1)); }
expect 1 "defocus --codec the container cannot hold" "$build/defocus" "$data" -o "$scratch/ffv1.mp4" --codec ffv1
stderr_one_line "defocus --codec the container cannot hold"
grep -v '^defocus: ' "$scratch/err" | grep -q . && {
    echo "FAIL a line on stderr that is not ours:"; grep -v '^defocus: ' "$scratch/err"; failures=$((failures + 1)); }
# One image from a clip: refused (BadInputTest), but one frame chosen with --start and --frames is fine.
expect 0 "defocus one frame of a clip to one image" "$build/defocus" "$data" -o "$scratch/one.png" --start 9 --frames 1 -q
[ -s "$scratch/one.png" ] || { echo "FAIL one.png not written"; failures=$((failures + 1)); }
# defocus-synthetic speaks as defocus: "error:" lines, an existing output refused without -y.
expect 2 "defocus-synthetic frame beyond the shot" "$build/defocus-synthetic" --frame 99 -o "$scratch/synthetic"
stderr_one_line "defocus-synthetic frame beyond the shot"
mkdir -p "$scratch/synthetic-exists" && : >"$scratch/synthetic-exists/color.exr"
expect 1 "defocus-synthetic existing output without -y" "$build/defocus-synthetic" -o "$scratch/synthetic-exists" \
    --no-reference
stderr_one_line "defocus-synthetic existing output without -y"
[ -s "$scratch/synthetic-exists/color.exr" ] && {
    echo "FAIL defocus-synthetic replaced color.exr without -y"; failures=$((failures + 1)); }
# The preview with a DISPLAY no X server answers (a stale one over ssh, an Xvfb gone): one line and
# 1, not Qt's abort (134).
stale=:$((7000 + $$ % 1000))
expect 1 "defocus-preview with a stale DISPLAY" env -u WAYLAND_DISPLAY -u QT_QPA_PLATFORM DISPLAY=$stale \
    "$build/defocus-preview" "$data"
stderr_one_line "defocus-preview with a stale DISPLAY"
# Progress where standard error is a log, not a terminal: a line per --progress-interval (0: per frame).
# Defect: a long run under Slurm or nohup printing its first and last lines only.
expect 0 "defocus progress lines in a log" "$build/defocus" "$data" -o "$scratch/progress/" --frames 3 --progress-interval 0
lines=$(grep -c 'info: [0-9]/3 frames, [0-9.]* fps, [0-9]*:[0-9][0-9] left' "$scratch/err")
[ "$lines" -eq 3 ] || { echo "FAIL $lines progress lines for 3 frames:"; sed 's/^/  stderr: /' "$scratch/err"; failures=$((failures + 1)); }

# 75: no EGL/GL (no vendor library): worth a retry elsewhere.
expect 75 "defocus without GL" no_gl "$build/defocus" "$data" -o "$scratch/nogl.mp4"
stderr_one_line "defocus without GL"
expect 75 "defocus-preview without GL" no_gl "$build/defocus-preview" "$data" --no-window
expect 75 "defocus-bench without GL" no_gl "$build/defocus-bench" --runs 1 --warmup 0 --data "$data"
expect 75 "defocus-soak without GL" no_gl "$build/defocus-soak" --frames 1
expect 75 "defocus-synthetic without GL" no_gl "$build/defocus-synthetic" -o "$scratch/synthetic"
expect 75 "defocus --egl-device without GL" no_gl "$build/defocus" "$data" -o "$scratch/nogl.mp4" --egl-device 1
expect 75 "defocus-bench-accuracy without GL" no_gl "$build/defocus-bench-accuracy" --scene synthetic -o "$scratch/acc"

# 130 and 143: Ctrl-C and SIGTERM while a clip plays (the preview, looping; defocus's own are in
# CliGLTest, which also checks the video written so far). The signal goes once a frame was shown
# (--trace prints each): a program started in the background by a non-interactive shell starts
# with SIGINT ignored (POSIX), so a Ctrl-C sent before it installs its handler (a loaded machine
# can take more than the 3 s this used to wait) is lost and the loop never ends.
for signal in INT TERM; do
    want=130
    [ "$signal" = TERM ] && want=143
    "$build/defocus-preview" "$data" --no-window --loop --no-pace -q --trace >"$scratch/out" 2>"$scratch/err" &
    pid=$!
    waited=0
    while ! grep -q '^shown frame' "$scratch/out" 2>/dev/null && kill -0 "$pid" 2>/dev/null && [ $waited -lt 1200 ]; do
        sleep 0.1
        waited=$((waited + 1))
    done
    kill -s "$signal" "$pid"
    wait "$pid"
    got=$?
    if [ "$got" -ne "$want" ]; then
        echo "FAIL defocus-preview SIG$signal: exit $got, expected $want"
        failures=$((failures + 1))
    else
        echo "ok   defocus-preview SIG$signal: exit $got"
    fi
    grep -q "frames shown" "$scratch/out" || { echo "FAIL defocus-preview SIG$signal: no summary on stdout"; failures=$((failures + 1)); }
done

echo "$failures failures"
[ "$failures" -eq 0 ]
