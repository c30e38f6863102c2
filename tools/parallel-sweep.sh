#!/bin/sh
# parallel-sweep.sh -- a sweep's shards through GNU Parallel, on this
# machine's cores or on ssh hosts, then merged and reported:
#   tools/parallel-sweep.sh [-j JOBS] [-S HOSTS] [-t THREADS] [-o OUT] SCRIPT.lua N [SCRIPT ARGS...]
# Shard I of N runs `shadowlab run SCRIPT --shard I/N --out OUT/shards/I --resume`
# (--resume: rerunning the recipe finishes what an interrupted run left), then
# `shadowlab merge -o OUT OUT/shards/*` and `shadowlab run SCRIPT --resume
# --out OUT` (everything is recorded, so it only writes OUT/index.html).
#   -j JOBS     shards at once per host (default: N locally, 1 per host with -S)
#   -S HOSTS    GNU Parallel --sshlogin list, e.g. "8/node1,8/node2" (":" is this
#               machine); every host needs this checkout, built, at the same path;
#               each shard's folder is copied back (--return)
#   -t THREADS  worker threads per shard (default: cores / JOBS, at least 1)
#   -o OUT      results folder (default reports/SCRIPT-NAME)
# $SHADOWLAB names the binary (default build/shadowlab).
set -eu
JOBS="" HOSTS="" THREADS="" OUT=""
while getopts "j:S:t:o:" opt; do
    case $opt in
    j) JOBS=$OPTARG ;; S) HOSTS=$OPTARG ;; t) THREADS=$OPTARG ;; o) OUT=$OPTARG ;;
    *) echo "usage: $0 [-j JOBS] [-S HOSTS] [-t THREADS] [-o OUT] SCRIPT.lua N [SCRIPT ARGS...]" >&2; exit 2 ;;
    esac
done
shift $((OPTIND - 1))
if [ $# -lt 2 ]; then
    echo "usage: $0 [-j JOBS] [-S HOSTS] [-t THREADS] [-o OUT] SCRIPT.lua N [SCRIPT ARGS...]" >&2
    exit 2
fi
SCRIPT=$1 N=$2
shift 2
case $N in '' | *[!0-9]* | 0) echo "$0: N must be a positive integer, got '$N'" >&2; exit 2 ;; esac
command -v parallel >/dev/null || { echo "$0: GNU parallel is missing (make deps installs it)" >&2; exit 1; }
SL=${SHADOWLAB:-build/shadowlab}
OUT=${OUT:-reports/$(basename "$SCRIPT" .lua)}
if [ -n "$HOSTS" ]; then
    JOBS=${JOBS:-1}
    REMOTE="--sshlogin $HOSTS --workdir $(pwd) --return $OUT/shards/{}"
else
    JOBS=${JOBS:-$N}
    REMOTE=""
fi
THREADS=${THREADS:-$(( $(nproc) / JOBS > 0 ? $(nproc) / JOBS : 1 ))}
mkdir -p "$OUT/shards"
# shellcheck disable=SC2086 # REMOTE is a list of options
seq 0 $((N - 1)) | parallel --will-cite --halt now,fail=1 --line-buffer --quote -j "$JOBS" $REMOTE \
    "$SL" run --threads "$THREADS" "$SCRIPT" --shard "{}/$N" --out "$OUT/shards/{}" --resume --quiet "$@"
"$SL" merge --force -o "$OUT" "$OUT"/shards/*
"$SL" run "$SCRIPT" --resume --out "$OUT" "$@"
