#!/usr/bin/env bash
# One shard of a library conversion per Slurm array task:
#
#   sbatch --array=0-99 scripts/slurm_encode.sh LIST OUTDIR [keyanim encode options...]
#
# Task I of N encodes entries I, I+N, I+2N, ... of LIST (one BVH path per line, relative to the
# directory sbatch was run from, or absolute) to the same paths below OUTDIR, skipping outputs
# that already load as valid files, and appends one JSON line per input to
# OUTDIR/report.I.jsonl (a report per task: appends are not atomic on NFS). Resubmitting the
# same array after a failure or a timeout redoes only what is missing. Set KEYANIM to the
# keyanim binary if it is not on PATH. Exit status: keyanim's (0 when every input of the shard
# is done).
#SBATCH --job-name=keyanim-encode
#SBATCH --cpus-per-task=1
#SBATCH --mem=4G
#SBATCH --time=24:00:00
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: sbatch --array=0-(N-1) $0 LIST OUTDIR [keyanim encode options...]" >&2
  exit 1
fi
LIST=$1 OUTDIR=$2
shift 2
: "${SLURM_ARRAY_TASK_ID:?run this under sbatch --array (SLURM_ARRAY_TASK_ID is not set)}"
: "${SLURM_ARRAY_TASK_COUNT:?run this under sbatch --array (SLURM_ARRAY_TASK_COUNT is not set)}"
# --array=1-100 numbers tasks from 1: shards are numbered from 0.
I=$((SLURM_ARRAY_TASK_ID - ${SLURM_ARRAY_TASK_MIN:-0}))
N=$SLURM_ARRAY_TASK_COUNT
mkdir -p "$OUTDIR"
exec "${KEYANIM:-keyanim}" encode --manifest "$LIST" -o "$OUTDIR" --shard "$I/$N" --skip-existing \
  --report "$OUTDIR/report.$I.jsonl" -j "${SLURM_CPUS_PER_TASK:-1}" "$@"
