#!/bin/sh
# run.sh -- the bench report's comparison with a stored baseline (report.sh,
# run.sh --save-baseline) on two hand-made raster_threads.csv: old/ is kept
# as the baseline, new/ is reported against it. In new/, bunny 2048^2 on 2
# threads got worse (speed-up 1.800 -> 1.400, ms_n 7.0 -> 9.8), million
# 2048^2 ran loaded (load 6.5 on 2 threads: its ms_n is not comparable),
# bunny 4096^2 is new and million 4096^2 vanished. No program is run and no
# time measured. Prints "bench: N passed, N failed"; under a second.
set -u
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
DATA=$ROOT/tests/bench
TMP=$(mktemp -d /tmp/shadowlab-bench-XXXXXX)
trap 'rm -rf "$TMP"' EXIT
pass=0
fail=0

ok() { pass=$((pass + 1)); echo "ok   $1"; }
no() { fail=$((fail + 1)); echo "FAIL $1: $2"; sed 's/^/    /' "$TMP/out" | head -8; }

# expect NAME STATUS PHRASES... -- COMMAND...: exit status, and each phrase
# (a fixed string) in stdout+stderr
expect() {
    name=$1; want=$2; shift 2
    : >"$TMP/phrases"
    while [ "$1" != "--" ]; do printf '%s\n' "$1" >>"$TMP/phrases"; shift; done
    shift
    "$@" >"$TMP/out" 2>&1
    got=$?
    if [ "$got" -ne "$want" ]; then no "$name" "exit $got, expected $want"; return; fi
    while IFS= read -r phrase; do
        if ! grep -qF -- "$phrase" "$TMP/out"; then no "$name" "output lacks '$phrase'"; return; fi
    done <"$TMP/phrases"
    ok "$name"
}

# has NAME FILE PHRASE: FILE holds PHRASE (a fixed string)
has() {
    if grep -qF -- "$3" "$2"; then ok "$1"; else cp "$2" "$TMP/out"; no "$1" "$2 lacks '$3'"; fi
}

# row FILE KEY: the report's table row of raster_threads.csv for KEY ("bunny | 69451 | 2048 | 2")
row() { grep -F "| $2 |" "$1" | head -n 1; }

mkdir -p "$TMP/old" "$TMP/new" "$TMP/empty"
cp "$DATA/old/raster_threads.csv" "$TMP/old/"
cp "$DATA/new/raster_threads.csv" "$TMP/new/"
base=$TMP/figures.csv

# A fresh clone has no baseline: the report says so and compares nothing.
expect "no baseline: report written" 0 "report:" -- "$ROOT/bench/report.sh" "$TMP/new" "$base"
has "no baseline: said" "$TMP/new/README.md" "No baseline ($base: absent)"
if grep -qF "(baseline, new/old)" "$TMP/new/README.md"; then no "no baseline: no comparison columns" "found"; else ok "no baseline: no comparison columns"; fi

# Only a finished run without failures becomes the baseline, written whole.
expect "save: unfinished run refused" 1 "complete.txt missing" -- "$ROOT/bench/run.sh" --save-baseline "$TMP/old" "$base"
[ ! -e "$base" ] && ok "save: nothing written when refused" || no "save: nothing written when refused" "$base exists"
echo "samples=256 threads=2 repeat=5 quick=0" > "$TMP/old/complete.txt"
echo "step 2: exit 1: llvmpipe" > "$TMP/old/failures.txt"
expect "save: run with failures refused" 1 "1 program(s) failed" -- "$ROOT/bench/run.sh" --save-baseline "$TMP/old" "$base"
rm "$TMP/old/failures.txt"
expect "save: finished run kept" 0 "8 figures" -- "$ROOT/bench/run.sh" --save-baseline "$TMP/old" "$base"
has "save: key and figure rows" "$base" 'raster_threads.csv,scene=bunny res=2048 threads=2,speedup,r+,1.800,2,aaaaaaa11111,"Test CPU, 2 cores",0.30,'
cp "$base" "$TMP/kept.csv"
expect "save: again" 0 "8 figures" -- "$ROOT/bench/run.sh" --save-baseline "$TMP/old" "$base"
cmp -s "$base" "$TMP/kept.csv" && ok "save: the old baseline replaced whole" || no "save: the old baseline replaced whole" "differs"
touch "$TMP/empty/complete.txt"
expect "save: no figures refused" 1 "no figures" -- "$ROOT/bench/run.sh" --save-baseline "$TMP/empty" "$base"
cmp -s "$base" "$TMP/kept.csv" && ok "save: baseline unchanged when refused" || no "save: baseline unchanged when refused" "changed"
set -- "$TMP"/*.tmp[0-9]*
[ -e "$1" ] && no "save: no temporary left" "$1" || ok "save: no temporary left"

# The comparison.
expect "compare: report written" 0 "report:" -- "$ROOT/bench/report.sh" "$TMP/new" "$base"
md=$TMP/new/README.md
has "compare: baseline's provenance" "$md" "(8 figures): commit aaaaaaa; cpu_model Test CPU, 2 cores; threads 1, 2;"
has "compare: summary counts" "$md" "Of this run's 8 figures: **2 worse**, 0 better, 3 within the noise, 1 not comparable"
has "compare: new and vanished counted" "$md" "2 new; 2 vanished"
row "$md" "bunny | 69451 | 2048 | 2" > "$TMP/row"
has "compare: worse speed-up marked" "$TMP/row" "| 1.400 | 1.800, 0.778 **worse** |"
has "compare: worse time marked" "$TMP/row" "| 9.800 | 7.000, 1.400 **worse** |"
row "$md" "bunny | 69451 | 2048 | 1" > "$TMP/row"
has "compare: unchanged row not marked" "$TMP/row" "| 1.000 | 1.000, 1.000 | 0.50 | aaaaaaa |"
row "$md" "bunny | 69451 | 4096 | 2" > "$TMP/row"
has "compare: missing key is new" "$TMP/row" "| 1.765 | new | 0.50 | new |"
row "$md" "million | 1000000 | 2048 | 2" > "$TMP/row"
has "compare: loaded run's time not comparable" "$TMP/row" "| 21.000 | 21.300, 0.986 (n/c) |"
has "compare: loaded run said" "$TMP/row" "loaded now (6.50) |"
has "compare: vanished listed" "$md" "| raster_threads.csv | scene=million res=4096 threads=2 | speedup | 1.875 |"
worst=$(grep -n "^| raster_threads.csv | scene=bunny res=2048 threads=2 | ms_n |" "$md" | cut -d: -f1)
next=$(grep -n "^| raster_threads.csv | scene=bunny res=2048 threads=2 | speedup |" "$md" | cut -d: -f1)
[ -n "$worst" ] && [ -n "$next" ] && [ "$worst" -lt "$next" ] && ok "compare: worst first" ||
    { cp "$md" "$TMP/out"; no "compare: worst first" "ms_n (1.400) not listed before speedup (1.286)"; }

# A baseline that is not one, and a bad noise margin: said, never a crash.
echo "scene,res" > "$TMP/bad.csv"
expect "bad baseline: said, nothing compared" 0 "line 1 is not the header" -- "$ROOT/bench/report.sh" "$TMP/new" "$TMP/bad.csv"
expect "bad margin: refused" 2 "BENCH_NOISE_RATIO = 'ten'" -- env BENCH_NOISE_RATIO=ten "$ROOT/bench/report.sh" "$TMP/new" "$base"

echo "bench: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
