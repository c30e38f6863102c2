#!/bin/sh
# demo.sh -- the README's demo (make demo): every registered technique compared
# with the Embree reference on a scene whose light it handles, the default
# scene (sphere light) first, else contact.lua (rect light). Writes
# OUTDIR/<scene>/ (reference and TECH .exr, .png, .json records),
# OUTDIR/metrics.md (one row per technique) and OUTDIR/metrics.txt (every run's
# full table). Any failing run fails the demo, naming it.
# Usage: scripts/demo.sh build/shadowlab OUTDIR
set -eu
SL=$1
OUT=$2
SCENES="scenes/sphere-on-plane.lua scenes/contact.lua" # in order of preference
mkdir -p "$OUT"
export SHADOWLAB_CACHE="${SHADOWLAB_CACHE:-$OUT/cache}"
LOG=$(mktemp -d /tmp/shadowlab-demo-XXXXXX)
trap 'rm -rf "$LOG"' EXIT

# run NAME COMMAND...: the command's output into $LOG/NAME.out; on failure
# its messages and a non-zero exit of the demo.
run() {
    job=$1; shift
    if ! "$@" >"$LOG/$job.out" 2>"$LOG/$job.err"; then
        cat "$LOG/$job.out" "$LOG/$job.err" >&2
        echo "demo: FAILED: $job ($*)" >&2
        exit 1
    fi
    cat "$LOG/$job.err" >&2
}

# The light kinds a technique handles, from `shadowlab list` ("  lights: a, b").
"$SL" list >"$LOG/list"
lights_of() {
    awk -v t="$1" '/^[^ ]/ { here = ($1 == t) } here && /^  lights:/ { sub(/^  lights: /, ""); print; exit }' "$LOG/list"
}

# Each scene's light kind, from the reference's first line "... (light 1: KIND, N triangles)".
for scene in $SCENES; do
    name=$(basename "$scene" .lua)
    run "reference-$name" "$SL" reference "$scene" -o "$OUT/$name"
    kind=$(sed -n '1s/.*(light 1: \([a-z_]*\),.*/\1/p' "$LOG/reference-$name.out")
    [ -n "$kind" ] || { echo "demo: no light kind in the reference of $scene" >&2; exit 1; }
    echo "$name $kind" >>"$LOG/kinds"
    echo "demo: reference of $name ($kind light) in $OUT/$name"
done

# Every technique on the first scene whose light kind it handles.
printf '| technique | scene | light | MAE | RMSE | penumbra RMSE | umbra leak | > 0.5 | evaluate (median of 5) |\n' >"$LOG/metrics.md"
printf '|---|---|---|---:|---:|---:|---:|---:|---:|\n' >>"$LOG/metrics.md"
for tech in $("$SL" list --names); do
    handled=$(lights_of "$tech" | tr -d ' ' | tr ',' ' ')
    name=$(awk -v h=" $handled " 'index(h, " " $2 " ") { print $1; exit }' "$LOG/kinds")
    [ -n "$name" ] || { echo "demo: FAILED: no demo scene has a light $tech handles ($handled)" >&2; exit 1; }
    run "$tech" "$SL" compare "scenes/$name.lua" -t "$tech" --repeat 5 -o "$OUT/$name"
    awk -v t="$tech" -v s="$name" '
        NR == 1 { sub(/.*\(light 1: /, ""); sub(/,.*/, ""); light = $0 }
        /^technique:/ { for (i = 1; i < NF; i++) if ($i == "evaluate") ev = $(i + 1) " s" }
        $1 == "all" { mae = $3; rmse = $4; wrong = $9 }
        $1 == "penumbra" { pen = $4 }
        $1 == "umbra" { leak = $7 } # leak_mean over the umbra (metrics.h ErrorStats)
        END {
            if (ev == "" || mae == "" || pen == "" || leak == "") { print "demo: no metrics in the output of " t > "/dev/stderr"; exit 1 }
            printf "| `%s` | %s | %s | %s | %s | %s | %s | %s | %s |\n", t, s, light, mae, rmse, pen, leak, wrong, ev
        }' "$LOG/$tech.out" >>"$LOG/metrics.md"
    echo "demo: $tech on $name"
done

for f in "$LOG"/reference-*.out; do cat "$f"; echo; done >"$OUT/metrics.txt.tmp"
for tech in $("$SL" list --names); do cat "$LOG/$tech.out"; echo; done >>"$OUT/metrics.txt.tmp"
mv "$OUT/metrics.txt.tmp" "$OUT/metrics.txt"
mv "$LOG/metrics.md" "$OUT/metrics.md"
cat "$OUT/metrics.md"
echo "demo: wrote $OUT (metrics: $OUT/metrics.md, every run's table: $OUT/metrics.txt)"
