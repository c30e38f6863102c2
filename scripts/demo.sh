#!/bin/sh
# demo.sh -- the README's demo: the default scene's Embree reference and every
# technique registered so far, compared, into reports/demo/ (images, EXRs,
# records and a metrics table). Usage: scripts/demo.sh build/shadowlab OUTDIR
set -eu
SL=$1
OUT=$2
SCENE=scenes/sphere-on-plane.lua
mkdir -p "$OUT"
export SHADOWLAB_CACHE="${SHADOWLAB_CACHE:-$OUT/cache}"
table="$OUT/metrics.txt"
: >"$table.tmp"
"$SL" reference "$SCENE" -o "$OUT" | tee -a "$table.tmp"
for tech in $("$SL" list --names); do
    echo >>"$table.tmp"
    "$SL" compare "$SCENE" -t "$tech" --repeat 5 -o "$OUT" | tee -a "$table.tmp"
done
mv "$table.tmp" "$table"
echo "demo: wrote $OUT (metrics table: $table)"
