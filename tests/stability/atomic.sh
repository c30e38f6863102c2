#!/bin/bash
# atomic.sh -- outputs are written atomically: runs of `compare` are killed
# (SIGKILL) at random points and every output file must then be either the
# previous version or a complete new one, byte for byte (EXR, PNG) or a
# whole JSON record; then runs of `reference` are killed while they compute
# and cache new references, and every cache entry they left must read back
# as a hit, never as a corrupt entry; then `stability -o` is killed while it
# writes its cases' scene files, and each file left must be whole. Leftover
# temporaries of killed runs are counted, not failed (a killed process
# cannot remove them).
# Usage: tests/stability/atomic.sh build/shadowlab [KILLS]. Prints "atomic: N passed, N failed".
set -u
SL=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
KILLS=${2:-16}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
TMP=$(mktemp -d /tmp/shadowlab-atomic-XXXXXX)
trap 'rm -rf "$TMP"' EXIT
export SHADOWLAB_CACHE="$TMP/cache"
export SHADOWLAB_PLUGIN_DIR=$(dirname "$SL")
SCENE=$ROOT/scenes/sphere-on-plane.lua
ARGS="-t hard -n 16 -s camera.width=64 -s camera.height=48"
FILES="hard.exr hard.png hard-shaded.png hard-error.png hard.json"
RANDOM=7 # reproducible kill points
pass=0
fail=0
leftovers=0

ok() { pass=$((pass + 1)); echo "ok   $1"; }
no() { fail=$((fail + 1)); echo "FAIL $1: $2"; }

json_whole() {
    if command -v python3 >/dev/null; then python3 -c 'import json,sys; json.load(open(sys.argv[1]))' "$1" 2>/dev/null
    else [ "$(head -c 1 "$1")" = "{" ] && [ "$(tail -c 2 "$1" | head -c 1)" = "}" ]; fi
}

# Complete outputs of the two configurations, to compare against.
for cfg in 1 2; do
    "$SL" compare "$SCENE" $ARGS -p offset_scale=$cfg -o "$TMP/whole$cfg" >/dev/null 2>&1 || no "atomic_setup_$cfg" "compare failed"
done
start=$(date +%s.%N)
"$SL" compare "$SCENE" $ARGS -p offset_scale=1 -o "$TMP/out" >/dev/null 2>&1
full=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.3f", b - a }')

# Each file in out/ is one of the complete versions; temporaries are counted and removed.
check_outputs() {
    local k=$1 bad=""
    for f in $FILES; do
        local p="$TMP/out/$f"
        if [ ! -e "$p" ]; then bad="$bad $f:missing"; continue; fi
        case $f in
        *.json) json_whole "$p" || bad="$bad $f:not-whole-json" ;;
        *) cmp -s "$p" "$TMP/whole1/$f" || cmp -s "$p" "$TMP/whole2/$f" || bad="$bad $f:neither-version" ;;
        esac
    done
    for p in "$TMP"/out/*; do
        case " $FILES " in *" $(basename "$p") "*) ;; *) leftovers=$((leftovers + 1)); rm -f "$p" ;; esac
    done
    if [ -z "$bad" ]; then ok "atomic_outputs_after_kill_$k"; else no "atomic_outputs_after_kill_$k" "$bad"; fi
}

# A kill point in [0, 1.2] x the run's duration; every other one in the last
# fifth, where the outputs are written.
kill_after() {
    local delay
    delay=$(awk -v f="$full" -v r="$RANDOM" -v late=$((RANDOM % 2)) \
        'BEGIN { u = (r % 1000) / 1000; printf "%.3f", f * (late ? 0.85 + 0.2 * u : 1.2 * u) }')
    "$@" >/dev/null 2>&1 &
    local pid=$!
    sleep "$delay"
    kill -9 "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
}

for k in $(seq 1 "$KILLS"); do
    kill_after "$SL" compare "$SCENE" $ARGS -p offset_scale=$((k % 2 + 1)) -o "$TMP/out"
    check_outputs "$k"
done

# Fresh references (a new seed each) killed mid-computation or mid-cache-write.
for k in $(seq 1 "$((KILLS / 2))"); do
    kill_after "$SL" reference "$SCENE" -n 64 --seed $((100 + k)) -s camera.width=64 -s camera.height=48 --no-png -o "$TMP/ref"
done
corrupt=0
for k in $(seq 1 "$((KILLS / 2))"); do
    "$SL" reference "$SCENE" -n 64 --seed $((100 + k)) -s camera.width=64 -s camera.height=48 --no-png -o "$TMP/ref" >"$TMP/ref.log" 2>&1
    grep -q cache_corrupt "$TMP/ref.log" "$TMP/ref/reference.json" && corrupt=$((corrupt + 1))
done
if [ "$corrupt" -eq 0 ]; then ok "atomic_reference_cache_never_corrupt"; else no atomic_reference_cache_never_corrupt "$corrupt corrupt entries"; fi

# `stability -o` killed while it writes its cases' files (scene.lua, meshes,
# light images): every file it left is byte for byte the one an uninterrupted
# run writes (the scene text is deterministic); temporaries are counted.
STAB="stability -t hard --quick --case zero_area_triangles"
compare_full=$full
"$SL" $STAB -o "$TMP/stab-whole" >/dev/null 2>&1 || no atomic_stability_setup "stability failed"
start=$(date +%s.%N)
"$SL" $STAB -o "$TMP/stab-time" >/dev/null 2>&1
full=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.3f", b - a }')
torn=""
whole=$(cd "$TMP/stab-whole/scenes" && find . -type f | wc -l)
for k in $(seq 1 "$KILLS"); do
    kill_after "$SL" $STAB -o "$TMP/stab-out"
    [ -d "$TMP/stab-out/scenes" ] || continue
    for p in $(cd "$TMP/stab-out/scenes" && find . -type f); do
        case $p in
        *.tmp*) leftovers=$((leftovers + 1)); rm -f "$TMP/stab-out/scenes/$p" ;;
        *) cmp -s "$TMP/stab-out/scenes/$p" "$TMP/stab-whole/scenes/$p" || torn="$torn $k:$p" ;;
        esac
    done
done
if [ "$whole" -ge 4 ] && [ -z "$torn" ]; then ok "atomic_stability_scene_files_after_${KILLS}_kills"
else no atomic_stability_scene_files "$whole files in a whole run; torn:$torn"; fi

echo "atomic kills: a full compare takes $compare_full s, a stability run $full s, $KILLS kills each, $leftovers temporaries left by killed runs"
echo "atomic: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
