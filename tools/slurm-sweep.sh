#!/bin/bash
# slurm-sweep.sh -- one shard of a sweep per Slurm array task:
#   sbatch --array=0-7 tools/slurm-sweep.sh SCRIPT.lua OUT [SCRIPT ARGS...]
# Task I of an array 0..N-1 runs `shadowlab run SCRIPT --shard I/N --out
# OUT/shards/I --resume` (so a requeued or preempted task continues where it
# stopped). When the array is done, merge and report, e.g. as a dependent job:
#   jid=$(sbatch --parsable --array=0-7 tools/slurm-sweep.sh SCRIPT.lua OUT)
#   sbatch --dependency=afterok:$jid --wrap \
#     "build/shadowlab merge --force -o OUT OUT/shards/* && build/shadowlab run SCRIPT.lua --resume --out OUT"
# Run it from the checkout (sbatch keeps the submit folder); $SHADOWLAB names
# the binary (default build/shadowlab). Threads: --cpus-per-task.
#SBATCH --job-name=shadowlab-sweep
#SBATCH --cpus-per-task=4
#SBATCH --time=04:00:00
#SBATCH --output=slurm-%A_%a.out
set -euo pipefail
if [ $# -lt 2 ]; then
    echo "usage: sbatch --array=0-(N-1) $0 SCRIPT.lua OUT [SCRIPT ARGS...]" >&2
    exit 2
fi
SCRIPT=$1 OUT=$2
shift 2
: "${SLURM_ARRAY_TASK_ID:?submit with sbatch --array=0-(N-1)}"
if [ "${SLURM_ARRAY_TASK_MIN:-0}" != 0 ]; then
    echo "$0: the array must start at 0 (--array=0-(N-1)), not ${SLURM_ARRAY_TASK_MIN}" >&2
    exit 2
fi
N=$((SLURM_ARRAY_TASK_MAX + 1))
cd "${SLURM_SUBMIT_DIR:-.}"
exec "${SHADOWLAB:-build/shadowlab}" run --threads "${SLURM_CPUS_PER_TASK:-1}" "$SCRIPT" \
    --shard "$SLURM_ARRAY_TASK_ID/$N" --out "$OUT/shards/$SLURM_ARRAY_TASK_ID" --resume --quiet "$@"
