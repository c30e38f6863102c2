#!/bin/sh
# run.sh -- the libFuzzer harnesses: each replays its whole seed corpus
# (tests/corpus/NAME: seeds and the regression inputs of every crash found,
# plus the project's own scenes, meshes and images as further seeds) and
# then fuzzes for SECONDS. New inputs go to a scratch corpus (make test)
# or to B/fuzz-corpus/NAME (the long run, KEEP=1), never into tests/corpus.
# Usage: tests/fuzz/run.sh BUILD_DIR [SECONDS per harness, default 6] [KEEP]
# Prints one line per harness and "fuzz: N passed, N failed".
set -u
B=$1
SECONDS_EACH=${2:-6}
KEEP=${3:-0}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
TMP=$(mktemp -d /tmp/shadowlab-fuzz-XXXXXX)
trap 'rm -rf "$TMP"' EXIT
export TMPDIR="$TMP"
export SHADOWLAB_PLUGIN_DIR="$ROOT/$B"
export SHADOWLAB_MODEL_PATH=/nonexistent # seeds name no models; keep runs fast and hermetic
# Leak checks in every harness, fuzz_png too: the leak it had off for was
# OIIO's on truncated PNGs (its read callback's message, 31 bytes per file),
# which image_read's structural check (io/image_check.c) now keeps OIIO from
# reaching; tests/lsan.supp names the system libraries' own allocations.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$ROOT/tests/lsan.supp:print_suppressions=0"
pass=0
fail=0

# Seeds that already live elsewhere in the tree.
more_seeds() {
    case $1 in
    scene) echo "$ROOT/scenes $ROOT/tests/scenes/bad" ;;
    obj | ply) echo "$ROOT/tests/data/meshes" ;;
    exr) echo "$ROOT/scenes/lights" ;;
    esac
}

for fuzzer in "$ROOT/$B"/fuzz_*; do
    name=$(basename "$fuzzer" | sed 's/^fuzz_//')
    seeds="$ROOT/tests/corpus/$name"
    [ -d "$seeds" ] || { echo "FAIL fuzz_$name: no seed corpus $seeds"; fail=$((fail + 1)); continue; }
    if [ "$KEEP" = 1 ]; then work="$ROOT/$B/fuzz-corpus/$name"; else work="$TMP/corpus-$name"; fi
    mkdir -p "$work" "$TMP/artifacts-$name"
    log="$TMP/$name.log"
    # A harness's dictionary (tests/fuzz/NAME.dict: tokens that reach deep paths, such as the
    # scene's metatable machinery), when it has one.
    dict=""
    [ -f "$ROOT/tests/fuzz/$name.dict" ] && dict="-dict=$ROOT/tests/fuzz/$name.dict"
    # -timeout above the scene sandbox's own limits (instructions ~2 s, 20 s wall).
    "$fuzzer" -max_total_time="$SECONDS_EACH" -timeout=30 -rss_limit_mb=4096 -detect_leaks=1 $dict \
        -artifact_prefix="$TMP/artifacts-$name/" -print_final_stats=1 "$work" "$seeds" $(more_seeds "$name") >"$log" 2>&1
    status=$?
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1)
    if [ "$status" -eq 0 ]; then
        pass=$((pass + 1))
        echo "ok   fuzz_$name: ${runs:-?} runs in ${SECONDS_EACH} s, $cov, $(ls "$seeds" | wc -l) seeds of its own"
    else
        fail=$((fail + 1))
        echo "FAIL fuzz_$name: exit $status; artifacts:"
        for a in "$TMP/artifacts-$name"/*; do
            [ -e "$a" ] || continue
            keep="$ROOT/$B/fuzz-crashes/$name"
            mkdir -p "$keep" && cp "$a" "$keep/"
            echo "    $keep/$(basename "$a") (add it to tests/corpus/$name and a regression test)"
        done
        grep -E 'ERROR|SUMMARY|runtime error|Timeout|out-of-memory' "$log" | head -5 | sed 's/^/    /'
    fi
done
echo "fuzz: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
