#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# `defocus --batch` end to end on this machine, no scheduler but GNU parallel:
#  1. scripts/batch-parallel.sh (two shards, two processes) over a manifest of five clips cut
#     from the bundled TUM clip, one with an input that does not exist: exit 1, the four good
#     clips done with their frame counts, the bad one's report says failed and names the file;
#     clips 0 and 1 (the same input and settings, one in each process) are byte-identical, PNG
#     frames and MP4 alike.
#  2. The same again: the four done clips are skipped, the failed one is tried again and fails
#     again (exit 1); once its input is there, a third run does it (exit 0) and nothing else.
#  3. One process stopped with SIGTERM in the middle of a clip: exit 143, nothing under that
#     clip's output name (its frames were in a hidden temporary folder, now gone) and no report;
#     the rerun finishes it and skips the clip done before the stop.
#   scripts/batch-test.sh build/defocus        (CTest: label batch; exit 77 = skipped)
set -u
defocus=$(realpath "${1:?usage: batch-test.sh DEFOCUS_BINARY}")
root=$(cd "$(dirname "$0")/.." && pwd)
command -v parallel >/dev/null || { echo "batch-test: SKIPPED: GNU parallel is not installed (apt-get install parallel)"; exit 77; }
fail() { echo "batch-test: FAILED: $*"; exit 1; }
tmp=$(mktemp -d /tmp/defocus-batch.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
tum="$root/data/tum_fr1_rpy"
# Frames of a folder output (TUM layout: the input's frame names, .png), not counting depth/ or
# files under a temporary name.
frames_on_disk() { find "$1" -maxdepth 1 -name '[!.]*.png' 2>/dev/null | wc -l; }

# ---- 1. GNU parallel, two shards --------------------------------------------------------------
{
  printf '%s\t-\tout/same-a/\t--frames 3 --focus 1.0 --quality fast\n' "$tum"
  printf '%s\t-\tout/same-b/\t--frames 3 --focus 1.0 --quality fast\n' "$tum"
  printf '{"input": "%s", "output": "out/c.mp4", "frames": 4, "focus": 1.2, "f-number": 1.4, "quality": "fast"}\n' "$tum"
  printf '%s\t-\tout/missing/\t--frames 2\n' "$tmp/no-such-clip"
  printf '{"input": "%s", "output": "out/d.mp4", "frames": 4, "focus": 1.2, "f-number": 1.4, "quality": "fast"}\n' "$tum"
} > clips.tsv
DEFOCUS="$defocus" JOBS=2 "$root/scripts/batch-parallel.sh" clips.tsv -q > run1.log 2>&1
status=$?
[ "$status" -eq 1 ] || { cat run1.log; fail "batch-parallel.sh exited $status, not 1 (one bad clip)"; }
for clip in same-a same-b; do
  [ "$(frames_on_disk out/$clip)" -eq 3 ] || fail "out/$clip has $(frames_on_disk out/$clip) frames, not 3"
  grep -q '"frames_out": 3,' out/$clip.report.json || fail "out/$clip.report.json does not count 3 frames out"
done
for clip in c d; do
  grep -q '"status": "done"' out/$clip.mp4.report.json || fail "out/$clip.mp4 is not reported done"
  grep -q '"frames_out": 4,' out/$clip.mp4.report.json || fail "out/$clip.mp4.report.json does not count 4 frames out"
done
grep -q '"status": "failed"' out/missing.report.json || fail "the missing clip's report does not say failed"
grep -q "no-such-clip" out/missing.report.json || fail "the missing clip's report does not name its input"
grep -q '"exit_status": 1' out/missing.report.json || fail "the missing clip's report does not give exit status 1"
for f in out/same-a/*.png out/same-a/depth/*.png out/same-a/*.txt; do
  cmp -s "$f" "out/same-b/${f#out/same-a/}" || fail "$f differs from its twin: the same clip rendered twice differs"
done
cmp -s out/c.mp4 out/d.mp4 || fail "out/c.mp4 and out/d.mp4 (the same clip and settings) differ"
grep -q '"renderer"' out/c.mp4.report.json || fail "the report does not name the renderer"
grep -q '"commit"' out/c.mp4.report.json || fail "the report does not name the commit"
echo "batch-test: parallel: 4 clips done, 1 failed with a report; the same clip twice is byte-identical"

# ---- 2. rerun: nothing done twice, the failed clip tried again until done ---------------------
DEFOCUS="$defocus" JOBS=2 "$root/scripts/batch-parallel.sh" clips.tsv -q > run2.log 2>&1
status=$?
[ "$status" -eq 1 ] || { cat run2.log; fail "the rerun with the input still missing exited $status, not 1"; }
skipped=$(grep -c 'done before, skipped' run2.log)
[ "$skipped" -eq 4 ] || { cat run2.log; fail "the rerun skipped $skipped clips, not the 4 done"; }
grep -q 'clip 3 (out/missing/): failed before, trying again' run2.log || { cat run2.log; fail "the rerun did not retry the failed clip"; }
grep -q ': done in' run2.log && fail "the rerun did a done clip again"
[ "$(grep -c 'no-such-clip' run2.log)" -eq 1 ] || { cat run2.log; fail "the missing input is not reported exactly once"; }
ln -s "$tum" "$tmp/no-such-clip"
DEFOCUS="$defocus" JOBS=2 "$root/scripts/batch-parallel.sh" clips.tsv -q > run3.log 2>&1
status=$?
[ "$status" -eq 0 ] || { cat run3.log; fail "the rerun with the input there exited $status, not 0"; }
grep -q '"status": "done"' out/missing.report.json || fail "the retried clip's report does not say done"
[ "$(frames_on_disk out/missing)" -eq 2 ] || fail "the retried clip has $(frames_on_disk out/missing) frames, not 2"
[ "$(grep -c ': done in' run3.log)" -eq 1 ] || { cat run3.log; fail "the third run did not do exactly the one clip"; }
echo "batch-test: rerun: 4 skipped, the failed clip retried (exit 1), then done once its input is there (exit 0)"

# ---- 3. SIGTERM mid-clip, then resume ----------------------------------------------------------
{
  printf '%s\t-\tlong/first/\t--frames 2 --focus 1.0 --quality fast\n' "$tum"
  printf '%s\t-\tlong/second/\t--focus 1.0 --quality high\n' "$tum"
} > long.tsv
"$defocus" --batch long.tsv -q > stop.log 2>&1 &
pid=$!
# Until the clip is done its frames are in the hidden folder beside its output.
for _ in $(seq 600); do
  [ "$(frames_on_disk long/.second.partial)" -ge 2 ] && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.1
done
[ "$(frames_on_disk long/.second.partial)" -ge 2 ] || { cat stop.log; fail "never saw the second clip in progress"; }
kill -TERM "$pid"
wait "$pid"
status=$?
[ "$status" -eq 143 ] || { cat stop.log; fail "SIGTERM mid-clip gave exit $status, not 143"; }
[ -e long/second.report.json ] && fail "the stopped clip has a report"
[ -e long/second ] && fail "the stopped clip left its output folder"
[ -e long/.second.partial ] && fail "the stopped clip left its temporary folder"
grep -q 'clip 1 (long/second/): not finished (status 143), no report' stop.log || { cat stop.log; fail "the batch does not say the clip was stopped"; }
grep -qi 'finalised\|removed' stop.log && { cat stop.log; fail "the batch speaks of a finalised or removed output"; }
[ -e long/first.report.json ] || fail "the clip finished before the stop has no report"
"$defocus" --batch long.tsv -q > resume.log 2>&1 || { cat resume.log; fail "the resumed batch failed"; }
grep -q 'clip 0 (long/first/): done before, skipped' resume.log || fail "the resumed batch did not skip the first clip"
[ "$(frames_on_disk long/second)" -eq 10 ] || fail "the resumed clip has $(frames_on_disk long/second) frames, not 10"
echo "batch-test: SIGTERM mid-clip: exit 143, nothing under the clip's output name; the rerun finished it"
echo "3 passed, 0 failed"
