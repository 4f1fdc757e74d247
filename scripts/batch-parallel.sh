#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# `defocus --batch` on one machine through GNU parallel: the manifest split into one shard per
# process, one process per core (or JOBS), the same contract as a Slurm array (defocus.sbatch).
#   scripts/batch-parallel.sh clips.tsv [defocus options]          JOBS=4 DEFOCUS=build/defocus ...
# Rerunning does only the clips not done yet: those without a report, or whose report says failed. Exit status: 0 when every shard finished, else
# the highest of the shards' statuses (143/130 stopped, 75 no GL, 2 bad command line, 1 a bad clip).
set -u
if [ $# -lt 1 ]; then
  echo "batch-parallel.sh: usage: scripts/batch-parallel.sh MANIFEST [defocus options]" >&2
  exit 2
fi
command -v parallel >/dev/null || { echo "batch-parallel.sh: GNU parallel is not installed (apt-get install parallel)" >&2; exit 2; }
jobs=${JOBS:-$(nproc)}
joblog=$(mktemp)
trap 'rm -f "$joblog"' EXIT
# The line itself: one shard per job, each job one defocus process.
seq 0 $((jobs - 1)) | parallel --will-cite -q --line-buffer --joblog "$joblog" -j "$jobs" \
  "${DEFOCUS:-defocus}" --batch "$@" --shard "{}/$jobs"
# parallel's own status counts failed jobs; the shards' statuses say what to do next.
awk 'NR > 1 && $7 > worst { worst = $7 } END { exit worst + 0 }' "$joblog"
