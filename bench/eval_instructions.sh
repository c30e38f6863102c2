#!/bin/sh
# eval_instructions.sh TECH [SCENE] -- the load-independent half of the
# 1 -> 2 thread figure: callgrind (--separate-threads) over one evaluation in
# the `techniques --only threads` configuration (640 x 480, light 1, 2
# threads), printing the instructions inside lab.c's evaluate_all but
# outside its parallel loop (serial, inside the timer), each thread's inside
# it, and the Amdahl bound 1 / (s + largest thread share). Valgrind runs one
# thread at a time; --fair-sched=yes hands them turns round-robin, so the
# split is that of two threads of equal speed (without it, evssm's was 48/52
# and its bound 1.93). OMP_WAIT_POLICY=passive keeps a waiting thread's
# spinning out of the counts.
# Usage (from the repository root, after make): bench/eval_instructions.sh sm
set -eu
tech=$1
scene=${2:-scenes/sphere-on-plane.lua}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
SHADOWLAB_MODEL_PATH=${SHADOWLAB_MODEL_PATH:-../shared/models} OMP_WAIT_POLICY=passive \
    valgrind --tool=callgrind --fair-sched=yes --separate-threads=yes --callgrind-out-file="$dir/cg" \
    build/shadowlab render "$scene" -t "$tech" -s camera.width=640 -s camera.height=480 --threads 2 \
    --repeat 1 --no-png -o "$dir/out" >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
# inclusive instructions of lab.c's function $2 in thread file $1 (0 if absent)
incl() {
    callgrind_annotate --inclusive=yes --threshold=100 "$1" 2>/dev/null |
        awk -v f="lab.c:$2 " 'index($0, f) { gsub(",", "", $1); print $1; found = 1; exit } END { if (!found) print 0 }'
}
main=$(ls "$dir"/cg-01)
all=$(incl "$main" evaluate_all)
loop=$(incl "$main" evaluate_all._omp_fn.0)
shares=$loop
for f in "$dir"/cg-0*; do
    [ "$f" = "$main" ] || shares="$shares $(incl "$f" evaluate_all._omp_fn.0)"
done
echo "$tech $all $loop $shares" | awk '{
    serial = $2 - $3; total = serial; big = 0
    for (i = 4; i <= NF; i++) { total += $i; if ($i > big) big = $i }
    printf "%s: %.1f M instructions in the timed evaluation, serial %d (%.4f%%), per thread", $1, total / 1e6,
           serial, 100 * serial / total
    for (i = 4; i <= NF; i++) if ($i > 0) printf " %.1f M", $i / 1e6
    printf ", bound %.3f\n", 1 / ((serial + big) / total)
}'
