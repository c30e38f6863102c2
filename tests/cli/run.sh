#!/bin/sh
# run.sh -- command-line tests: exit statuses, messages, outputs, cache use.
# Usage: tests/cli/run.sh build/shadowlab. Prints "cli: N passed, N failed".
set -u
SL=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BAD=$ROOT/tests/scenes/bad
TMP=$(mktemp -d /tmp/shadowlab-cli-XXXXXX)
trap 'rm -rf "$TMP"' EXIT
export SHADOWLAB_CACHE="$TMP/cache"
pass=0
fail=0

ok() { pass=$((pass + 1)); echo "ok   $1"; }
no() { fail=$((fail + 1)); echo "FAIL $1: $2"; sed 's/^/    /' "$TMP/err" | head -5; }

# expect NAME STATUS WORDS... -- COMMAND...: exit status and words in stderr+stdout
expect() {
    name=$1; want=$2; shift 2
    words=""
    while [ "$1" != "--" ]; do words="$words|$1"; shift; done
    shift
    "$@" >"$TMP/out" 2>"$TMP/err"
    got=$?
    cat "$TMP/out" >>"$TMP/err"
    if [ "$got" -ne "$want" ]; then no "$name" "exit $got, expected $want"; return; fi
    for w in $(echo "${words#|}" | tr '|' ' '); do
        if ! grep -q -- "$w" "$TMP/err"; then no "$name" "output lacks '$w'"; return; fi
    done
    ok "$name"
}

# A broken scene: exit 1, the words, and nothing written to the output folder.
broken() {
    case_name=$1; scene=$2; shift 2
    out="$TMP/out-$case_name"
    expect "bad_scene_$case_name" 1 "$@" -- "$SL" compare "$scene" -t hard -n 4 -o "$out"
    if [ -e "$out" ] && [ -n "$(ls -A "$out")" ]; then no "bad_scene_${case_name}_leaves_no_output" "files in $out"
    else ok "bad_scene_${case_name}_leaves_no_output"; fi
}

broken unknown_key "$BAD/unknown-key.lua" "unknown-key.lua" "objects\[1\].sise" "valid:"
broken negative_radius "$BAD/negative-radius.lua" "lights\[1\].radius" "(0, 1e+07]"
broken missing_model "$BAD/missing-model.lua" "no-such-model.obj" "SHADOWLAB_MODEL_PATH"
broken nan_vertex "$BAD/nan-vertex.lua" "nan-vertex.obj:3" "not finite"
broken empty_mesh "$BAD/empty-mesh.lua" "empty.obj" "no triangles"
broken face_out_of_range "$BAD/face-out-of-range.lua" "bad-index.obj:5" "out of range"
broken unreadable_file "$BAD/does-not-exist.lua" "does-not-exist.lua" "cannot open"
broken directory_as_scene "$BAD" "bad"
broken loop_forever "$BAD/loop-forever.lua" "loop-forever.lua" "instruction limit"
broken os_execute "$BAD/os-execute.lua" "os-execute.lua" "os"
if [ -e /tmp/shadowlab-pwned ]; then no sandbox_ran_command "/tmp/shadowlab-pwned exists"; else ok sandbox_ran_no_command; fi

SCENE=$ROOT/scenes/sphere-on-plane.lua
expect usage_no_command 2 "usage" -- "$SL"
expect usage_unknown_command 2 "unknown command" -- "$SL" frobnicate
expect usage_unknown_option 2 "unknown option '--frob'" -- "$SL" compare "$SCENE" -t hard --frob
expect usage_unknown_technique 2 "unknown technique 'nope'" "hard" -- "$SL" render "$SCENE" -t nope
expect usage_param_out_of_range 2 "offset_scale" "\[0, 10000\]" -- "$SL" render "$SCENE" -t hard -p offset_scale=-1
expect usage_unknown_param 2 "unknown parameter 'K'" -- "$SL" render "$SCENE" -t hard -p K=3
expect usage_samples_range 2 "\[1, 1048576\]" -- "$SL" reference "$SCENE" -n 0
expect usage_stratified_needs_square 2 "square" -- "$SL" reference "$SCENE" -n 10 --pattern stratified
expect runtime_light_out_of_range 1 "--light 3 outside \[1, 1\]" -- "$SL" render "$SCENE" -t hard -l 3 -o "$TMP/l3"
expect help_compare 0 "--samples" "--measure" -- "$SL" compare --help
expect list_shows_hard 0 "hard" "offset_scale" "course" -- "$SL" list

"$SL" list --json >"$TMP/list.json" 2>"$TMP/err"
if command -v python3 >/dev/null && python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert any(t["name"]=="hard" for t in d)' "$TMP/list.json" 2>>"$TMP/err"; then
    ok list_json_parses
elif ! command -v python3 >/dev/null; then ok list_json_parses_skipped_no_python; else no list_json_parses "invalid JSON"; fi

"$SL" list --markdown >"$TMP/techniques.md" 2>"$TMP/err"
if cmp -s "$TMP/techniques.md" "$ROOT/docs/techniques.md"; then ok docs_techniques_generated_from_registry
else no docs_techniques_generated_from_registry "docs/techniques.md is stale: run make docs"; fi

# compare writes every output and its record; a second run reads the cache.
OUT=$TMP/cmp
SMALL="-s camera.width=96 -s camera.height=72"
expect compare_writes_outputs 0 "MAE" "penumbra" "computed" -- "$SL" compare "$SCENE" -t hard -n 64 $SMALL -o "$OUT"
for f in hard.exr hard.json hard.png hard-shaded.png hard-error.png; do
    if [ -s "$OUT/$f" ]; then ok "compare_wrote_$f"; else no "compare_wrote_$f" "missing"; fi
done
expect compare_second_run_hits_cache 0 "cache_hit" -- "$SL" compare "$SCENE" -t hard -n 64 $SMALL -o "$OUT"
if grep -q '"origin": "cache_hit"' "$OUT/hard.json"; then ok record_says_cache_hit; else no record_says_cache_hit "$(grep origin "$OUT/hard.json")"; fi
for key in '"scene"' '"hash"' '"params"' '"offset_scale"' '"timings_s"' '"resources"' '"commit"' '"noise_rms"' '"penumbra"' '"threads"'; do
    if grep -q "$key" "$OUT/hard.json"; then ok "record_has_$key"; else no "record_has_$key" "missing"; fi
done
expect reference_irradiance 0 "irradiance" -- "$SL" reference "$SCENE" --measure irradiance -n 16 $SMALL -o "$TMP/irr"
expect render_without_png 0 "evaluate" -- "$SL" render "$SCENE" -t hard --no-png $SMALL -o "$TMP/nopng"
if [ -e "$TMP/nopng/hard.png" ]; then no render_no_png_writes_none "png written"; else ok render_no_png_writes_none; fi

# shadowlab aliasing: the sampling-error report of a technique's map (docs/aliasing.md)
PLANE=$ROOT/scenes/overhead-plane.lua
AL="$TMP/aliasing"
expect aliasing_writes_outputs 0 "undersampled" "storage factor" -- "$SL" aliasing "$PLANE" -t pcf -p projection=lispsm -p fit=body -p cascades=2 $SMALL --frustum 6 -o "$AL"
for f in aliasing.exr aliasing.json aliasing.png aliasing-cascade.png aliasing-hist.csv aliasing-depth.csv aliasing-axis.csv; do
    if [ -s "$AL/$f" ]; then ok "aliasing_wrote_$f"; else no "aliasing_wrote_$f" "missing"; fi
done
expect aliasing_refuses_a_mapless_technique 2 "hard renders no shadow map" -- "$SL" aliasing "$PLANE" -t hard -o "$TMP/al-hard"
expect aliasing_refuses_bad_frustum 2 "--frustum expects" -- "$SL" aliasing "$PLANE" --frustum -3 -o "$TMP/al-bad"
expect aliasing_param_range 2 "cascades" "\[1, 16\]" -- "$SL" aliasing "$PLANE" -p cascades=17 -o "$TMP/al-bad"

echo "cli: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
