#!/bin/sh
# run.sh -- runs the bare-Embree benchmark on each benchmark scene, from the
# repository root, appending one row per scene to
# reports/bench/reference_throughput.csv. The bunny runs only when
# scenes/bunny.lua exists and its model is on SHADOWLAB_MODEL_PATH (default
# ../shared/models beside the repository) or in glmark2's models folder.
# Usage: bench/run.sh BINARY SAMPLES THREADS REPEAT
set -eu
[ $# -eq 4 ] || { echo "usage: $0 BINARY SAMPLES THREADS REPEAT" >&2; exit 2; }
bin=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
cd "$(dirname "$0")/.."
export SHADOWLAB_MODEL_PATH="${SHADOWLAB_MODEL_PATH:-$(pwd)/../shared/models}"
csv=reports/bench/reference_throughput.csv

bench() {
    "$bin" "$1" -n "$2" --threads "$3" --repeat "$4" -o "$csv"
}

# Is a bunny model in any folder of the model search path?
bunny_found() {
    for d in $(echo "$SHADOWLAB_MODEL_PATH" | tr ':' ' ') /usr/share/glmark2/models; do
        for f in stanford-bunny.obj bunny.obj; do
            [ -f "$d/$f" ] && return 0
        done
    done
    return 1
}

bench scenes/sphere-on-plane.lua "$2" "$3" "$4"
if [ ! -f scenes/bunny.lua ]; then
    echo "note: scenes/bunny.lua does not exist yet; bunny skipped"
elif ! bunny_found; then
    echo "note: no bunny model on SHADOWLAB_MODEL_PATH ($SHADOWLAB_MODEL_PATH) or in glmark2's models; bunny skipped"
else
    bench scenes/bunny.lua "$2" "$3" "$4"
fi
echo "results: $csv"

# seed 002 §4's "approximately 20% slower": single_sample_rt against hard,
# on the sphere scene (its Fig. 4) across light radii and on the bunny (a
# tessellated model, its Fig. 5) when found.
ss="$(dirname "$bin")/single_sample_overhead"
if [ -x "$ss" ]; then
    ss_scenes=scenes/sphere-on-plane.lua
    [ -f scenes/bunny.lua ] && bunny_found && ss_scenes="$ss_scenes scenes/bunny.lua"
    "$ss" --radius 0.05 --radius 0.2 --radius 0.4 --radius 0.8 --threads "$3" --repeat "$4" $ss_scenes
fi
