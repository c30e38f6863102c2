#!/bin/sh
# run.sh -- every bench program of issue 8, from the repository root, into a
# fresh reports/bench/ (CSV per program, then report.sh's README.md, tables
# and gnuplot plots). Every row carries threads, commit, CPU model, the
# 1-minute load average and the date; figures are ratios measured within one
# run (medians of per-round ratios). QUICK=1 uses fewer sizes and repeats.
# The bunny scenes need stanford-bunny.obj on SHADOWLAB_MODEL_PATH (default
# ../shared/models) or glmark2-data's bunny.obj (scripts/deps.sh installs it).
# Usage: bench/run.sh BIN_DIR SAMPLES THREADS REPEAT
set -eu
[ $# -eq 4 ] || { echo "usage: $0 BIN_DIR SAMPLES THREADS REPEAT" >&2; exit 2; }
bin=$(cd "$1" && pwd)
samples=$2 threads=$3 repeat=$4
cd "$(dirname "$0")/.."
export SHADOWLAB_MODEL_PATH="${SHADOWLAB_MODEL_PATH:-$(pwd)/../shared/models}"
out=reports/bench
quick=${QUICK:-0}
mkdir -p "$out"
rm -f "$out"/*.csv "$out"/*.dat "$out"/*.gp "$out"/*.svg "$out"/*.png "$out"/README.md
uptime > "$out/load.txt"

step() { echo; echo "== $* (load: $(cut -d' ' -f1-3 /proc/loadavg))"; }

if [ "$quick" = 1 ]; then res="--res 1024 --res 2048"; q=--quick; else res="--res 1024 --res 2048 --res 4096"; q=; fi

step "1. reference against a bare Embree loop"
for s in scenes/sphere-on-plane.lua scenes/bunny.lua; do
    "$bin/bare_embree" "$s" -n "$samples" --threads "$threads" --repeat "$repeat" -o "$out/reference_throughput.csv"
done
"$bin/single_sample_overhead" --radius 0.05 --radius 0.4 --threads "$threads" --repeat "$repeat" \
    -o "$out/single_sample_overhead.csv" scenes/sphere-on-plane.lua scenes/bunny.lua

step "2. the rasterizer and PCF against llvmpipe ($threads threads each)"
"$bin/llvmpipe" $res --threads "$threads" --repeat "$repeat" -o "$out" scenes/million.lua
"$bin/llvmpipe" $res --pcf 3 --pcf 7 --pcf 15 --threads "$threads" --repeat "$repeat" -o "$out" scenes/bunny.lua

step "3. cost growth (1 thread: curves, not speed) and constant time in K"
"$bin/techniques" --only growth $q --threads 1 --repeat 3 -o "$out"
"$bin/techniques" --only constant --threads "$threads" --repeat "$repeat" -o "$out"

step "4. sweep reuse"
"$bin/sweep_reuse" --threads "$threads" -o "$out"

step "5. thread scaling, 1 -> $threads threads"
"$bin/raster_threads" --res 2048 --threads "$threads" --repeat "$repeat" -o "$out" scenes/bunny.lua scenes/million.lua
"$bin/techniques" --only threads --threads "$threads" --repeat "$repeat" -o "$out"

step "6. peak memory against the resources' bytes, 4096^2 maps"
"$bin/memory" --res 4096 --threads "$threads" -o "$out"

step "7. start-up"
"$bin/startup" "$bin/../shadowlab" --repeat 21 -o "$out"

uptime >> "$out/load.txt"
./bench/report.sh "$out"
