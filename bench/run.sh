#!/bin/sh
# run.sh -- every bench program of issue 8, from the repository root, into a
# fresh reports/bench/ (CSV per program, then report.sh's README.md, tables
# and gnuplot plots). Every row carries threads, commit, CPU model, the
# 1-minute load average and the date; figures are ratios measured within one
# run (medians of per-round ratios). QUICK=1 uses fewer sizes and repeats.
# A program that fails is reported (and listed in failures.txt and the
# report); the others still run, and the script exits 1 at the end.
# The bunny scenes need stanford-bunny.obj on SHADOWLAB_MODEL_PATH (default
# ../shared/models) or glmark2-data's bunny.obj (scripts/deps.sh installs it).
# A run that got to its end leaves complete.txt (its settings); --save-baseline
# keeps such a run's figures, if no program failed, as the baseline the next
# reports compare with (bench/baseline/README.md).
# Usage: bench/run.sh BIN_DIR SAMPLES THREADS REPEAT
#        bench/run.sh --save-baseline [DIR [BASELINE]]  (reports/bench, bench/baseline/figures.csv)
set -u
if [ "${1:-}" = --save-baseline ]; then
    [ $# -le 3 ] || { echo "usage: $0 --save-baseline [DIR [BASELINE]]" >&2; exit 2; }
    root=$(cd "$(dirname "$0")/.." && pwd)
    dir=${2:-$root/reports/bench}
    [ -f "$dir/complete.txt" ] ||
        { echo "run.sh: $dir/complete.txt missing: not a finished run (make bench first); baseline unchanged" >&2; exit 1; }
    [ ! -s "$dir/failures.txt" ] ||
        { echo "run.sh: $dir/failures.txt: $(wc -l < "$dir/failures.txt") program(s) failed in that run; baseline unchanged" >&2; exit 1; }
    exec "$root/bench/report.sh" --save "$dir" "${3:-$root/bench/baseline/figures.csv}"
fi
[ $# -eq 4 ] || { echo "usage: $0 BIN_DIR SAMPLES THREADS REPEAT" >&2; exit 2; }
bin=$(cd "$1" && pwd) || exit 2
samples=$2 threads=$3 repeat=$4
cd "$(dirname "$0")/.." || exit 2
export SHADOWLAB_MODEL_PATH="${SHADOWLAB_MODEL_PATH:-$(pwd)/../shared/models}"
out=reports/bench
quick=${QUICK:-0}
mkdir -p "$out" || exit 1
rm -f "$out"/*.csv "$out"/*.dat "$out"/*.gp "$out"/*.svg "$out"/*.png "$out"/README.md "$out"/failures.txt "$out"/complete.txt \
    "$out"/steps.txt
uptime > "$out/load.txt"
failures=0
current=

# step N TITLE: closes the previous step with its wall time (steps.txt, and the log), opens the next.
step_start=
step_close() {
    [ -n "$step_start" ] || return 0
    secs=$(( $(date +%s) - step_start ))
    echo "  step $current in all: $secs s" >> "$out/steps.txt"
    echo "-- step $current took $secs s"
}
step() {
    step_close; current=$1; step_start=$(date +%s)
    echo "step $*" >> "$out/steps.txt"
    echo; echo "== $* (load: $(cut -d' ' -f1-3 /proc/loadavg))"
}

# run PROGRAM ARGS...: a failure is reported and recorded, and the run goes on.
# stdout line-buffered, so a program's errors land between its lines, not in them.
# Each program's wall time goes to steps.txt under its step.
run() {
    t0=$(date +%s)
    stdbuf -oL "$@"
    rc=$?
    echo "  $(( $(date +%s) - t0 )) s: $*" | sed "s|$bin/||" >> "$out/steps.txt"
    [ "$rc" -eq 0 ] && return 0
    failures=$((failures + 1))
    echo "run.sh: step $current: FAILED (exit $rc): $*" >&2
    echo "step $current: exit $rc: $*" >> "$out/failures.txt"
}

# QUICK: two map sizes, growth's and threads' maps lowered (techniques.c), and the
# reference against bare Embree at half the light samples (its rows say which).
if [ "$quick" = 1 ]; then
    res="--res 1024 --res 2048"; q=--quick; ref_samples=$((samples / 2))
else
    res="--res 1024 --res 2048 --res 4096"; q=; ref_samples=$samples
fi
[ "$ref_samples" -ge 1 ] || ref_samples=1

step 1 "reference against a bare Embree loop"
for s in scenes/sphere-on-plane.lua scenes/bunny.lua; do
    run "$bin/bare_embree" "$s" -n "$ref_samples" --threads "$threads" --repeat "$repeat" -o "$out/reference_throughput.csv"
done
run "$bin/single_sample_overhead" --radius 0.05 --radius 0.4 --threads "$threads" --repeat "$repeat" -o "$out" \
    scenes/sphere-on-plane.lua scenes/bunny.lua

step 2 "the rasterizer and PCF against llvmpipe ($threads threads each)"
run "$bin/llvmpipe" $res --threads "$threads" --repeat "$repeat" -o "$out" scenes/million.lua
run "$bin/llvmpipe" $res --pcf 3 --pcf 7 --pcf 15 --threads "$threads" --repeat "$repeat" -o "$out" scenes/bunny.lua

step 3 "cost growth (1 thread: curves, not speed) and constant time in K"
run "$bin/techniques" --only growth $q --threads 1 --repeat 3 -o "$out"
run "$bin/techniques" --only constant --threads "$threads" --repeat "$repeat" -o "$out"
# esm's SAT path alone: its classifier's PCF fallback (and the one it takes
# where a SAT window loses precision at large exponents) costs K^2.
run "$bin/techniques" --only constant -t esm -p classifier=none -p exponent=20 --threads "$threads" \
    --repeat "$repeat" -o "$out"
# constant in the light's size (course §5.2.2, §5.2.5): every soft technique on the bunny, radius 0.05 and 0.8
run "$bin/techniques" --only lightsize $q --threads "$threads" --repeat "$repeat" -o "$out" scenes/bunny.lua
# pcss at its defaults reads 16 + 16 Poisson taps whatever the light: constant by construction; reading every
# texel of its windows (up to its max_radius = 32 texels) it grows
run "$bin/techniques" --only lightsize -t pcss -p sampling=exhaustive $q --threads "$threads" --repeat "$repeat" \
    -o "$out" scenes/bunny.lua
# machine-independent work counters beside the hand counts (160x120; exits 1 on a disagreement)
run "$bin/techniques" --only work --threads "$threads" -o "$out"

step 4 "sweep reuse"
run "$bin/sweep_reuse" --threads "$threads" -o "$out"

step 5 "thread scaling, 1 2 4 ... $threads threads"
for s in scenes/sphere-on-plane.lua scenes/bunny.lua; do
    run "$bin/bare_embree" "$s" -n "$ref_samples" --threads "$threads" --repeat "$repeat" --scaling \
        -o "$out/reference_scaling.csv"
done
run "$bin/cpu_speed" --label before --threads "$threads" -o "$out"
run "$bin/raster_threads" --res 2048 --threads "$threads" --repeat "$repeat" -o "$out" scenes/bunny.lua scenes/million.lua
for kib in 256 4096; do run "$bin/coherence" --kib "$kib" --repeat 9 -o "$out"; done
run "$bin/techniques" --only threads $q --threads "$threads" --repeat "$repeat" -o "$out"
run "$bin/cpu_speed" --label after --threads "$threads" -o "$out"

step 6 "peak memory against the resources' bytes, 4096^2 maps"
run "$bin/memory" --res 4096 --threads "$threads" -o "$out"

step 7 "start-up"
run "$bin/startup" "$bin/../shadowlab" --repeat 21 -o "$out"

step 8 "geometry: silhouette extraction against triangles, shadow volumes against sm and hard, view sample mapping against the reference"
run "$bin/geometry" $q --threads "$threads" --repeat "$repeat" -o "$out" scenes/bunny.lua scenes/terrain.lua

step 9 "issue 15: cost against slices, texel budget and light size; issue 16: error against time at pcss's RMSE"
# occlusion textures linear in slices; backprojection linear in its texel budget T, and against the light's
# radius with a budget that never binds (256 lexels); the bitmask accumulation against the area one
if [ "$quick" = 1 ]; then sweep_map="-p map_size=512"; else sweep_map=; fi
# (512^2: at 1024^2 its N-buffer slice tables pass the 2 GiB cap from 8 slices on, 2.09 GiB)
run "$bin/techniques" --only sweep -t occlusion_textures --sweep slices=4,6,8,12,16 -p map_size=512 \
    --threads "$threads" --repeat "$repeat" -o "$out"
run "$bin/techniques" --only sweep -t backprojection --sweep budget=2,4,8,16,32,64 $sweep_map --threads "$threads" \
    --repeat "$repeat" -o "$out"
run "$bin/techniques" --only sweep -t backprojection -p budget=256 --sweep 'lights[1].radius=0.05,0.1,0.2,0.4,0.8' \
    $sweep_map --threads "$threads" --repeat "$repeat" -o "$out"
run "$bin/techniques" --only sweep -t backprojection --sweep accumulate=bitmask,area $sweep_map --threads "$threads" \
    --repeat "$repeat" -o "$out"
# the prefiltered PCSS family against pcss at pcss's penumbra RMSE (map sizes 64 ... 2048; QUICK: ... 1024, 160x120)
for s in scenes/bunny.lua scenes/sphere-on-plane.lua scenes/overlap.lua; do
    run "$bin/techniques" --only matched $q --samples "$samples" --threads "$threads" --repeat "$repeat" -o "$out" "$s"
done

step_close
uptime >> "$out/load.txt"
current=report
start=$(date +%s.%N)
run ./bench/report.sh "$out"
echo "run.sh: report written in $(echo "$(date +%s.%N) $start" | awk '{ printf "%.2f", $1 - $2 }') s"
echo "samples=$samples threads=$threads repeat=$repeat quick=$quick finished=$(date -u +%Y-%m-%dT%H:%M:%SZ)" > "$out/complete.txt"
if [ "$failures" -gt 0 ]; then
    echo >&2
    echo "run.sh: $failures program(s) FAILED; the other results are in $out:" >&2
    sed 's/^/  /' "$out/failures.txt" >&2
    exit 1
fi
