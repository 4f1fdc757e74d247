#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# A one-node Slurm cluster on this machine runs `defocus --batch` through scripts/defocus.sbatch:
# munged, slurmctld and slurmd from Debian's packages, configured in a temporary folder (state,
# spool, logs, munge key and socket all there, removed at the end; nothing under /etc or /var is
# touched), an `sbatch --array=0-1` over a manifest of six small clips cut from the bundled TUM
# clip, one task cancelled (scancel) in the middle of a clip and requeued. Checks: the cancelled
# task exits 143 and leaves no partial output and no report for the clip it had in hand; after the
# requeue every clip has exactly one "done" line in the logs, a report saying done, and as many
# frames on disk and in its report as it was asked for; the clip the task had finished before the
# cancel is skipped, not done again.
#   scripts/slurm-test.sh build/defocus        (CTest: label slurm; exit 77 = skipped)
# Needs root (slurmd starts jobs as their user) and slurm-wlm + munge (scripts/setup.sh).
set -u
defocus=$(realpath "${1:?usage: slurm-test.sh DEFOCUS_BINARY}")
root=$(cd "$(dirname "$0")/.." && pwd)
skip() { echo "slurm-test: SKIPPED: $*"; exit 77; }
fail() { echo "slurm-test: FAILED: $*"; show_logs; exit 1; }

for tool in munged slurmctld slurmd sbatch scontrol squeue sinfo scancel; do
  command -v "$tool" >/dev/null || skip "'$tool' is not installed (apt-get install slurm-wlm munge)"
done
[ "$(id -u)" -eq 0 ] || skip "slurmd must run as root to start jobs; run as root"

tmp=$(mktemp -d /tmp/defocus-slurm.XXXXXX)
pids=()
cleanup() {
  # Stop only the daemons this script started, then remove everything it made.
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null
  done
  rm -rf "$tmp"
}
trap cleanup EXIT
show_logs() {
  for f in "$tmp"/log/*.log "$tmp"/work/*.log; do
    [ -f "$f" ] && { echo "---- $f (last 15 lines)"; tail -n 15 "$f"; }
  done
}

# ---- munge, with its own key and socket ---------------------------------------------------------
mkdir -p "$tmp/munge" "$tmp/state" "$tmp/spool" "$tmp/log" "$tmp/work"
chmod 700 "$tmp/munge"
chmod 755 "$tmp"
head -c 1024 /dev/urandom > "$tmp/munge/munge.key"
chmod 400 "$tmp/munge/munge.key"
munged -F --force --key-file="$tmp/munge/munge.key" --socket="$tmp/munge/munge.socket" \
  --pid-file="$tmp/munge/munged.pid" --log-file="$tmp/log/munged.log" --seed-file="$tmp/munge/seed" \
  >"$tmp/log/munged.out" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [ -S "$tmp/munge/munge.socket" ] && break; sleep 0.1; done
[ -S "$tmp/munge/munge.socket" ] || skip "munged did not start: $(tail -n 3 "$tmp/log/munged.out")"

# ---- slurm.conf: one node, this machine's CPUs, no accounting, no cgroups -----------------------
cpus=$(nproc)
port=$((20000 + RANDOM % 20000))
export SLURM_CONF="$tmp/slurm.conf"
cat > "$SLURM_CONF" <<CONF
ClusterName=defocustest
SlurmctldHost=localhost
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/munge.socket
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
KillWait=10
NodeName=node0 NodeHostname=localhost NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=node0 Default=YES MaxTime=30 State=UP
CONF
slurmctld -D -f "$SLURM_CONF" >"$tmp/log/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" -N node0 >"$tmp/log/slurmd.out" 2>&1 &
pids+=($!)
up=""
for _ in $(seq 100); do
  if sinfo -h -o %T 2>/dev/null | grep -q idle; then up=1; break; fi
  sleep 0.2
done
[ -n "$up" ] || skip "the one-node cluster did not come up: $(tail -n 2 "$tmp/log/slurmctld.out" "$tmp/log/slurmd.out" | tr '\n' ' ')"
echo "slurm-test: one-node cluster up ($(sinfo -h -o '%N %c CPUs %T'), slurm $(sinfo -V | cut -d' ' -f2))"

# ---- six clips from the bundled TUM clip; shard k % 2 -> task 0 gets clips 0,2,4, task 1 1,3,5 --
# Clip 3, the second of task 1, is the long one: every frame, full size, cancelled mid-clip.
tum="$root/data/tum_fr1_rpy"
declare -A frames=([0]=2 [1]=2 [2]=3 [3]=10 [4]=2 [5]=3)
manifest="$tmp/work/clips.tsv"
: > "$manifest"
for k in 0 1 2 3 4 5; do
  options="--frames ${frames[$k]} --focus 1.0 --quality fast"
  [ "$k" -eq 3 ] && options="--frames ${frames[$k]} --focus 1.0 --quality high"
  printf '%s\t-\tout/clip%s/\t%s\n' "$tum" "$k" "$options" >> "$manifest"
done

cd "$tmp/work"
# Frames of a folder output (TUM layout: the input's frame names), not files under a temporary name.
frames_on_disk() { find "$1" -maxdepth 1 -name '[!.]*.png' 2>/dev/null | wc -l; }
job=$(DEFOCUS="$defocus" sbatch --parsable --array=0-1 --cpus-per-task=1 --time=10 \
  --output="$tmp/work/task-%a.log" "$root/scripts/defocus.sbatch" "$manifest" -q) ||
  fail "sbatch refused the job"
echo "slurm-test: submitted array job $job"

# Cancel task 1 once clip 3 has frames on disk (in the hidden folder beside its output, until the
# clip is done) but no report.
cancelled=""
for _ in $(seq 600); do
  n=$(frames_on_disk out/.clip3.partial)
  if [ "$n" -ge 2 ] && [ ! -e out/clip3.report.json ]; then
    scancel "${job}_1" && cancelled=1
    echo "slurm-test: cancelled task 1 with $n frames of clip 3 written"
    break
  fi
  [ -e out/clip3.report.json ] && break
  sleep 0.1
done
[ -n "$cancelled" ] || fail "never saw clip 3 in progress to cancel it"

state() { scontrol show job "${job}_$1" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | head -n 1; }
exitcode() { scontrol show job "${job}_$1" 2>/dev/null | sed -n 's/.* ExitCode=\([0-9]*\):.*/\1/p' | head -n 1; }
for _ in $(seq 600); do [ "$(state 1)" = CANCELLED ] && break; sleep 0.1; done
[ "$(state 1)" = CANCELLED ] || fail "task 1 is $(state 1), not CANCELLED"
[ "$(exitcode 1)" = 143 ] || fail "task 1 exited $(exitcode 1), not 143 (SIGTERM)"
[ -e out/clip3.report.json ] && fail "the cancelled clip 3 has a report"
[ -e out/clip3 ] && fail "the cancelled clip 3 left an output folder"
[ -e out/.clip3.partial ] && fail "the cancelled clip 3 left its temporary folder"
[ -e out/clip1.report.json ] || fail "clip 1, finished before the cancel, has no report"

# slurmd revoked job 1's credential when it killed the task, and a launch whose credential is dated
# the same second counts as revoked ("Job credential revoked": the task fails with exit 1). So the
# restart waits out that second. StartTime=now: a requeued job waits ~2 min otherwise, and a start
# time in the future waits for the scheduler's next periodic pass (a minute).
sleep 1.1
scontrol requeue "${job}_1" || fail "scontrol requeue ${job}_1 failed"
scontrol update jobid="${job}_1" StartTime=now >/dev/null
echo "slurm-test: requeued task 1"
for _ in $(seq 1800); do
  [ -z "$(squeue -h -j "$job" 2>/dev/null)" ] && break
  sleep 0.1
done
[ -z "$(squeue -h -j "$job")" ] || fail "the array did not finish: $(squeue -h -j "$job")"
for t in 0 1; do
  [ "$(exitcode $t)" = 0 ] || fail "task $t ended with $(exitcode $t) ($(state $t))"
done

# ---- every clip complete, exactly once --------------------------------------------------------
for k in 0 1 2 3 4 5; do
  report="out/clip$k.report.json"
  [ -f "$report" ] || fail "clip $k has no report"
  grep -q '"status": "done"' "$report" || fail "clip $k's report does not say done: $(head -c 300 "$report")"
  grep -q "\"frames_out\": ${frames[$k]}," "$report" || fail "clip $k's report does not count ${frames[$k]} frames out"
  on_disk=$(frames_on_disk "out/clip$k")
  [ "$on_disk" -eq "${frames[$k]}" ] || fail "clip $k has $on_disk frames on disk, not ${frames[$k]}"
  done_lines=$(cat task-*.log | grep -c "defocus: clip $k (out/clip$k/): done in")
  [ "$done_lines" -eq 1 ] || fail "clip $k was done $done_lines times"
done
grep -q "defocus: clip 1 (out/clip1/): done before, skipped" task-1.log || fail "the requeued task did not skip clip 1"
grep -q "clip 3 (out/clip3/): not finished (status 143), no report" task-1.log ||
  fail "task 1's log does not say clip 3 was stopped"
leftovers=$(find out -name '*.tmp-*' | wc -l)
[ "$leftovers" -eq 0 ] || fail "$leftovers temporary report files left"
echo "slurm-test: 6 clips complete exactly once; task 1 cancelled mid-clip (exit 143), requeued, skipped its done clip"
echo "1 passed, 0 failed"
