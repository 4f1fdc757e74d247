#!/bin/sh
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

# 75: no EGL/GL (no vendor library): worth a retry elsewhere.
expect 75 "defocus without GL" no_gl "$build/defocus" "$data" -o "$scratch/nogl.mp4"
stderr_one_line "defocus without GL"
expect 75 "defocus-preview without GL" no_gl "$build/defocus-preview" "$data" --no-window
expect 75 "defocus-bench without GL" no_gl "$build/defocus-bench" --runs 1 --warmup 0 --data "$data"
expect 75 "defocus-soak without GL" no_gl "$build/defocus-soak" --frames 1
expect 75 "defocus-synthetic without GL" no_gl "$build/defocus-synthetic" -o "$scratch/synthetic"
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
