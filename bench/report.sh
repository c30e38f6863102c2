#!/bin/sh
# report.sh -- reports/bench/README.md from the CSVs run.sh wrote: one table
# per bench (the columns that carry the figures, then threads, load and
# commit), the programs that failed (failures.txt), and gnuplot plots (SVG
# and PNG, with their .gp scripts and .dat data): llvmpipe speed-ups against
# map size, cost growth per axis, and the thread-scaling curves per technique
# beside bare Embree's, each with its target or ideal drawn in. Every figure
# stands beside the baseline's (bench/baseline/README.md), with a summary of
# what got worse at the top.
# Usage: bench/report.sh DIR [BASELINE]      DIR/README.md, against BASELINE
#                                            (default bench/baseline/figures.csv)
#        bench/report.sh --save DIR BASELINE DIR's figures as the baseline,
#                                            BASELINE written whole or not at all
set -eu
mode=report
if [ "${1:-}" = --save ]; then
    [ $# -eq 3 ] || { echo "usage: $0 --save DIR BASELINE" >&2; exit 2; }
    mode=save; shift
fi
dir=${1:-reports/bench}
baseline=${2:-$(dirname "$0")/baseline/figures.csv}
md="$dir/README.md"
[ -d "$dir" ] || { echo "report: $dir: no such folder (the CSVs of a bench run)" >&2; exit 2; }
# Noise margins, a fraction of the baseline's figure (bench/README.md).
noise_ratio=${BENCH_NOISE_RATIO:-0.10}
noise_absolute=${BENCH_NOISE_ABSOLUTE:-0.25}
for v in "BENCH_NOISE_RATIO=$noise_ratio" "BENCH_NOISE_ABSOLUTE=$noise_absolute"; do
    echo "${v#*=}" | grep -Eq '^(0|[1-9][0-9]*)?([.][0-9]+)?$' && [ -n "${v#*=}" ] ||
        { echo "report: ${v%%=*} = '${v#*=}': expected a fraction of the baseline's figure, 0 or more (0.1 is 10%)" >&2; exit 2; }
done

# The CSV reading shared by every awk below: split_csv (RFC 4180 quotes,
# doubled quotes inside them), csv_field (quotes a field that needs it),
# is_number (a finite decimal: "nan", "inf" and empty cells are not figures).
CSV_AWK='
function split_csv(line, out,    n, i, c, q, field) {
    n = 0; field = ""; q = 0
    for (i = 1; i <= length(line); i++) {
        c = substr(line, i, 1)
        if (c == "\"") { if (q && substr(line, i + 1, 1) == "\"") { field = field c; i++ } else q = !q; continue }
        if (c == "," && !q) { out[++n] = field; field = ""; continue }
        field = field c
    }
    out[++n] = field
    return n
}
function csv_field(s) { if (s !~ /[",]/) return s; gsub(/"/, "\"\"", s); return "\"" s "\"" }
function is_number(s) { return s ~ /^[-+]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][-+]?[0-9]+)?$/ }
'

# The baseline (bench/baseline/README.md): one row per figure of a stored run,
# BASE_HEADER's columns; "key" joins the key columns as NAME=VALUE.
BASE_HEADER="table,key,figure,kind,value,threads,commit,cpu_model,load_1min,date"

# MARKS: one line per CSV, "CSV KEYS | FIGURES"; marks CSV gives the rest of
# CSV's line. KEYS are the columns that
# identify a measurement (scene, technique, size, threads, settings...; a key
# that comes again in the same CSV, as growth.csv's map_size when it is also
# a technique's main parameter, is told apart by its order: "#2"). FIGURES
# are NAME:KD, a figure of kind K and direction D (+ higher is better,
# - lower is better):
#   r  a ratio measured within one run (noise margin 10%: BENCH_NOISE_RATIO),
#   a  an absolute time, rate or size, compared across runs (margin 25%:
#      BENCH_NOISE_ABSOLUTE; only on the same cpu_model with neither run
#      loaded, else "n/c", not comparable; loaded: a 1-minute load above
#      the row's threads + 1),
#   c  a machine-independent count (margin 0: any change is real).
# A CSV not listed here is shown as it is and named in the summary; a CSV
# shown twice is compared in the first of its tables.
MARKS='
reference_throughput.csv    scene samples threads | reference_rays_per_s:a+ ratio:r+
single_sample_overhead.csv  scene radius threads | shadow_ratio:r- ray_tracer_ratio:r-
llvmpipe_depth.csv          scene res threads | shadowlab_ms:a- speedup:r+ vs_fill:r- coverage_mismatch:c-
llvmpipe_pcf.csv            scene width height map_res K threads | shadowlab_ms:a- speedup:r+ samples_off:c-
growth.csv                  technique axis value scene light settings threads | frame_ms:a-
constant_time.csv           technique settings prefilter light threads | frame_max_ms:a- ratio:r-
light_size.csv              technique map_size scene threads | frame_large_ms:a- ratio:r-
work.csv                    technique light settings | texel_fetches_per_sample:c- rays_per_sample:c- frame_bytes_built:c-
sweep_reuse.csv             sweep technique points threads | sweep_ms:a- ratio:r- builds:c-
reference_scaling.csv       scene rays threads | reference_ms_n:a- reference_speedup:r+ ratio:r+
raster_threads.csv          scene res threads | ms_n:a- speedup:r+
coherence.csv               kib | handover_ns:a- other_over_own:r-
cpu_speed.csv               label loop cpu | alone_ms:a- dynamic_bound:r+ static_bound:r+
threads_eval.csv            technique threads light settings width height | ms_n:a- speedup:r+
memory.csv                  technique map_res light | peak_rss_mib:a- ratio:r-
startup.csv                 command | first_line_ms:a- exit_ms:a-
silhouette.csv              segments threads | ns_per_triangle:a- ns_per_triangle_over_smallest:r-
volumes.csv                 scene versus map_size threads | shadow_volume_ms:a- ratio:r-
'
marks() { printf '%s\n' "$MARKS" | awk -v t="$1" '$1 == t { sub(/^[^ ]+ +/, ""); print; exit }'; }

# table CSV COLUMNS...: a markdown table of the named columns of CSV, each
# figure (marks) beside the baseline's for the same key: in report mode each
# figure gets one more column, the baseline's value and new/old with its
# mark, and the row a "baseline" column (the commit, "new" for a key the
# baseline lacks, and why its absolute figures do not compare); every
# comparison goes to $cmp for the summary. In save mode (report.sh --save)
# each figure goes to $save as a baseline row instead.
table() {
    f="$dir/$1"; name=$1; shift
    if [ ! -f "$f" ]; then
        [ "$mode" = save ] || { echo "(not run: $name missing)"; echo; }
        return 0
    fi
    case " $compared " in
    *" $name "*) spec='' again=1 ;;
    *) spec=$(marks "$name") again=0 compared="$compared $name" ;;
    esac
    awk -v tname="$name" -v cols="$*" -v marks="$spec" -v again="$again" -v base="$base_in" -v has_base="$has_base" -v cmp="$cmp" -v save="$save" \
        -v noise_r="$noise_ratio" -v noise_a="$noise_absolute" "$CSV_AWK"'
        # A row is loaded when its 1-minute load exceeds its own thread count
        # by more than one: more than one other thread ran beside the bench.
        function loaded(load, threads) { return is_number(load) && is_number(threads) && load + 0 > threads + 1 }
        # Sets was, change and status for figure c (kind and direction kd) of
        # the row with key `key`, and records the comparison in cmp. bad is
        # old/new for a figure where higher is better, new/old otherwise
        # (above 1: worse); a side at 0 has no ratio, only a direction.
        function compare(key, c, kd, now, comparable,    old, new, bad, margin) {
            bad = 0
            if (!((key, c) in bval)) { was = "-"; change = "new"; status = "new" }
            else if (!is_number(bval[key, c]) || !is_number(now) || bval[key, c] + 0 < 0 || now + 0 < 0) {
                was = bval[key, c]; change = "n/a"; status = "n/a"    # empty, non-finite or negative
            } else {
                old = bval[key, c] + 0; was = bval[key, c]; new = now + 0
                if (old == new) { bad = 1; change = "1.000" }
                else if (old == 0 || new == 0) { bad = (new > old) == (substr(kd, 2, 1) == "-") ? 1e30 : 1e-30; change = new == 0 ? "to 0" : "from 0" }
                else { bad = substr(kd, 2, 1) == "+" ? old / new : new / old; change = sprintf("%.3f", new / old) }
                margin = substr(kd, 1, 1) == "r" ? noise_r : substr(kd, 1, 1) == "a" ? noise_a : 0
                if (substr(kd, 1, 1) == "a" && !comparable) { status = "n/c"; change = change " (n/c)" }
                else if (bad > 1 + margin) { status = "worse"; change = change " **worse**" }
                else if (bad < 1 / (1 + margin)) { status = "better"; change = change " better" }
                else status = "same"
            }
            printf "%s\t%g\t%s\t%s\t%s\t%s\t%s\t%s\n", status, bad, tname, key, c, was, now, change >> cmp
        }
        # The baseline row of figure k of the current row (save mode).
        function save_figure(key, k) {
            print csv_field(tname) "," csv_field(key) "," want[k] "," role[k] "," csv_field(f[idx[k]]) "," \
                  csv_field(f[col["threads"]]) "," csv_field(f[col["commit"]]) "," csv_field(f[col["cpu_model"]]) "," \
                  csv_field(f[col["load_1min"]]) "," csv_field(f[col["date"]]) >> save
        }
        # want[1..m]: the columns shown; role[k] the kind and direction of a
        # figure (a figure not shown is added at the end); keys[1..nk].
        BEGIN {
            m = split(cols, want, " ")
            split(marks, part, "[|]"); nk = split(part[1], keys, " "); nf = split(part[2], figs, " ")
            for (j = 1; j <= nf; j++) {
                if (figs[j] !~ /.:[rac][-+]$/) {
                    printf "report: marks %s: \"%s\": expected NAME:KD, K one of r, a, c and D + or -\n", tname, figs[j] > "/dev/stderr"
                    exit 2
                }
                c = figs[j]; sub(/:[rac][-+]$/, "", c)
                for (k = 1; k <= m && want[k] != c; k++) ;
                if (k > m) want[++m] = c
                role[k] = substr(figs[j], length(figs[j]) - 1)
            }
            # A table with no figure is shown as it is, and named in the summary
            # unless its CSV was compared in an earlier table.
            if (!nf && has_base) { if (!again) printf "unmarked\t0\t%s\n", tname >> cmp; has_base = 0 }
        }
        FILENAME == base {
            if (FNR == 1) { nb = split_csv($0, bh); for (i = 1; i <= nb; i++) bcol[bh[i]] = i; next }
            split_csv($0, b)
            if (b[bcol["table"]] != tname) next
            key = b[bcol["key"]]
            bval[key, b[bcol["figure"]]] = b[bcol["value"]]
            bcommit[key] = b[bcol["commit"]]; bcpu[key] = b[bcol["cpu_model"]]
            bload[key] = b[bcol["load_1min"]]; bthreads[key] = b[bcol["threads"]]
            next
        }
        FNR == 1 {
            n = split_csv($0, head)
            for (i = 1; i <= n; i++) col[head[i]] = i
            for (k = 1; k <= m; k++) idx[k] = col[want[k]]
            for (k = 1; k <= m; k++) if (!idx[k]) printf "report: note: %s has no column %s\n", tname, want[k] > "/dev/stderr"
            for (j = 1; j <= nk; j++) if (!col[keys[j]]) printf "report: note: %s has no key column %s\n", tname, keys[j] > "/dev/stderr"
            if (save != "") next
            line = "|"; sep = "|"
            for (k = 1; k <= m; k++) {
                line = line " " want[k] " |"; sep = sep "---|"
                if (has_base && (k in role)) { line = line " " want[k] " (baseline, new/old) |"; sep = sep "---|" }
            }
            if (has_base) { line = line " baseline |"; sep = sep "---|" }
            print line; print sep; next
        }
        {
            split_csv($0, f); key = ""
            for (j = 1; j <= nk; j++) key = key (j > 1 ? " " : "") keys[j] "=" f[col[keys[j]]]
            if (++repeat[key] > 1) key = key " #" repeat[key]
            if (save != "") { for (k = 1; k <= m; k++) if (k in role) save_figure(key, k); next }
            note = ""
            if (has_base) {
                if (!(key in bcommit)) note = "new"
                else {
                    note = substr(bcommit[key], 1, 7)
                    if (bcpu[key] != f[col["cpu_model"]]) note = note ", other cpu_model (" bcpu[key] ")"
                    if (loaded(bload[key], bthreads[key])) note = note ", baseline loaded (" bload[key] ")"
                    if (loaded(f[col["load_1min"]], f[col["threads"]])) note = note ", loaded now (" f[col["load_1min"]] ")"
                }
            }
            comparable = note !~ /other cpu_model|loaded/
            line = "|"
            for (k = 1; k <= m; k++) {
                line = line " " f[idx[k]] " |"
                if (has_base && (k in role)) { compare(key, want[k], role[k], f[idx[k]], comparable); line = line " " (status == "new" ? "new" : was ", " change) " |" }
            }
            if (has_base) line = line " " note " |"
            print line
        }' "$base_in" "$f"
    [ "$mode" = save ] || echo
}

# column CSV NAME...: the named columns, space-separated, for gnuplot.
column() {
    f="$1"; shift
    awk -F, -v cols="$*" 'NR == 1 { m = split(cols, want, " "); for (k = 1; k <= m; k++) for (i = 1; i <= NF; i++)
                                        if ($i == want[k]) idx[k] = i; next }
                          { line = ""; for (k = 1; k <= m; k++) line = line (k > 1 ? " " : "") $(idx[k]); print line }' "$f"
}

# plot NAME SCRIPT: run a gnuplot script into NAME.svg and NAME.png.
plot() {
    printf '%s\n' "$2" > "$dir/$1.gp"
    for t in svg png; do
        case $t in svg) term="svg size 800,500 dynamic";; png) term="pngcairo size 800,500";; esac
        gnuplot -e "set terminal $term; set output '$dir/$1.$t'" "$dir/$1.gp" 2>/dev/null ||
            echo "report: note: gnuplot could not draw $1.$t" >&2
    done
}

plots() {
    if [ -f "$dir/llvmpipe_depth.csv" ]; then
        for s in $(column "$dir/llvmpipe_depth.csv" scene | sort -u); do
            column "$dir/llvmpipe_depth.csv" scene res speedup | awk -v s="$s" '$1 == s { print $2, $3 }' > "$dir/llvmpipe_$s.dat"
        done
        plot llvmpipe_depth "set title 'Depth-only shadow map: speed-up over llvmpipe (same threads)'
set xlabel 'map size (texels per side)'; set ylabel 'llvmpipe time / shadowlab time'; set logscale x 2; set grid
set yrange [0:2.5<*]
plot $(for s in $(column "$dir/llvmpipe_depth.csv" scene | sort -u); do printf "'%s' using 1:2 with linespoints title '%s', " "$dir/llvmpipe_$s.dat" "$s"; done) 2 with lines dashtype 2 title 'target 2x'"
    fi
    if [ -f "$dir/growth.csv" ]; then
        for axis in map_size triangles image_width; do
            script="set title 'Frame time against $axis (1 thread)'
set xlabel '$axis'; set ylabel 'frame time (ms)'; set logscale xy; set grid; set key outside right
plot "
            first=1
            for t in $(column "$dir/growth.csv" technique | sort -u); do
                column "$dir/growth.csv" technique axis value frame_ms |
                    awk -v t="$t" -v a="$axis" '$1 == t && $2 == a && NF == 4 { print $3, $4 }' > "$dir/growth_${axis}_$t.dat"
                [ -s "$dir/growth_${axis}_$t.dat" ] || { rm -f "$dir/growth_${axis}_$t.dat"; continue; }
                [ $first = 1 ] || script="$script, "
                script="$script'$dir/growth_${axis}_$t.dat' using 1:2 with linespoints title '$t'"
                first=0
            done
            plot "growth_$axis" "$script"
        done
        script="set title 'Frame time against each technique''s main parameter, relative to its first value (1 thread)'
set xlabel 'parameter value / first value'; set ylabel 'frame time / frame time at the first value'
set logscale xy; set grid; set key outside right
plot "
        first=1
        for t in $(column "$dir/growth.csv" technique | sort -u); do
            column "$dir/growth.csv" technique axis value frame_ms |
                awk -v t="$t" '$1 == t && NF == 4 && $2 != "map_size" && $2 != "triangles" && $2 != "image_width" {
                    if (!v0) { v0 = $3; f0 = $4; name = $2 } print $3 / v0, $4 / f0, name }' > "$dir/growth_main_$t.dat"
            [ -s "$dir/growth_main_$t.dat" ] || { rm -f "$dir/growth_main_$t.dat"; continue; }
            p=$(awk 'NR == 1 { print $3 }' "$dir/growth_main_$t.dat")
            [ $first = 1 ] || script="$script, "
            script="$script'$dir/growth_main_$t.dat' using 1:2 with linespoints title '$t ($p)'"
            first=0
        done
        [ $first = 1 ] || plot growth_main "$script"
    fi
    if [ -f "$dir/sweep.csv" ]; then
        script="set title 'Evaluation time per lit candidate per unit of the axis, over the first value''s'
set xlabel 'axis value'; set ylabel 'ratio (linear: 1)'; set logscale x; set grid; set key outside right noenhanced
plot 1 with lines dashtype 2 title 'linear'"
        for ta in $(column "$dir/sweep.csv" technique axis | tr ' ' '@' | sort -u); do
            t=${ta%%@*} a=${ta#*@} d="$dir/sweep_$(printf '%s' "$ta" | tr -c 'A-Za-z0-9_\n' '_').dat"
            column "$dir/sweep.csv" technique axis value per_value_ratio |
                awk -v t="$t" -v a="$a" '$1 == t && $2 == a && $3 ~ /^[-+.0-9eE]+$/ && $4 != "nan" { print $3, $4 }' > "$d"
            [ -s "$d" ] || { rm -f "$d"; continue; } # an enum's choices, or a 0: no per-unit figure
            script="$script, '$d' using 1:2 with linespoints title '$t, $a'"
        done
        plot sweep "$script"
    fi
    if [ -f "$dir/matched_curve.csv" ]; then
        for s in $(column "$dir/matched_curve.csv" scene | sort -u); do
            script="set title 'Penumbra RMSE against frame time, $s (map sizes 64 ... 2048)'
set xlabel 'frame time (ms)'; set ylabel 'penumbra RMSE'; set logscale xy; set grid; set key outside right noenhanced
plot "
            first=1
            for t in $(column "$dir/matched_curve.csv" technique | sort -u); do
                d="$dir/matched_${s}_$t.dat"
                column "$dir/matched_curve.csv" scene technique frame_ms penumbra_rmse |
                    awk -v s="$s" -v t="$t" '$1 == s && $2 == t { print $3, $4 }' > "$d"
                [ -s "$d" ] || { rm -f "$d"; continue; }
                [ $first = 1 ] || script="$script, "
                script="$script'$d' using 1:2 with linespoints title '$t'"
                first=0
            done
            [ $first = 1 ] || plot "matched_$s" "$script"
        done
    fi
    if [ -f "$dir/threads_eval.csv" ]; then
        n=$(column "$dir/threads_eval.csv" threads | sort -n | tail -1)
        script="set title 'Speed-up over 1 thread, 1 to $n threads (ideal: the diagonal)'
set xlabel 'threads'; set ylabel 't(1) / t(threads)'; set logscale xy 2; set grid; set key outside right noenhanced
plot x with lines dashtype 2 title 'ideal'"
        for t in $(column "$dir/threads_eval.csv" technique | sort -u); do
            column "$dir/threads_eval.csv" technique threads speedup | awk -v t="$t" '$1 == t { print $2, $3 }' \
                > "$dir/threads_$t.dat"
            script="$script, '$dir/threads_$t.dat' using 1:2 with linespoints title '$t'"
        done
        # the curves' control loop (techniques.c), the median over techniques per thread count
        column "$dir/threads_eval.csv" threads machine_speedup | sort -k1,1n -k2,2g |
            awk 'NF == 2 && $2 != "" { if ($1 != t && n) { print t, m[int((n + 1) / 2)]; n = 0 } t = $1; m[++n] = $2 }
                 END { if (n) print t, m[int((n + 1) / 2)] }' > "$dir/threads_machine.dat"
        [ -s "$dir/threads_machine.dat" ] &&
            script="$script, '$dir/threads_machine.dat' using 1:2 with linespoints lw 3 dashtype 3 title 'machine (control loop)'"
        if [ -f "$dir/reference_scaling.csv" ]; then
            for s in $(column "$dir/reference_scaling.csv" scene | sort -u); do
                column "$dir/reference_scaling.csv" scene threads bare_speedup |
                    awk -v s="$s" '$1 == s { print $2, $3 }' > "$dir/threads_bare_$s.dat"
                script="$script, '$dir/threads_bare_$s.dat' using 1:2 with linespoints lw 3 title 'bare Embree, $s'"
            done
        fi
        plot threads_eval "$script"
    fi
}

# vanished: the baseline's figures this run has no row for (from $cmp, the
# tables' comparisons), as markdown rows.
vanished() {
    awk -F'\t' -v base="$baseline" "$CSV_AWK"'
        FILENAME != base { seen[$3, $4, $5] = 1; next }
        FNR == 1 { nb = split_csv($0, bh); for (i = 1; i <= nb; i++) bcol[bh[i]] = i; next }
        {
            split_csv($0, b)
            if (!((b[bcol["table"]], b[bcol["key"]], b[bcol["figure"]]) in seen))
                print "| " b[bcol["table"]] " | " b[bcol["key"]] " | " b[bcol["figure"]] " | " b[bcol["value"]] " |"
        }' "$cmp" "$baseline"
}

# summary: the baseline's provenance, then how many figures got worse,
# better, stayed within the noise, are new or vanished, and the worse ones
# listed worst first, then the vanished ones.
summary() {
    echo "## Against the baseline"
    echo
    if [ "$has_base" = 0 ]; then
        echo "No baseline ($baseline: $base_problem), so nothing is compared. \`make bench-baseline\` keeps a"
        echo "finished run's figures as one (bench/baseline/README.md)."
        echo
        return
    fi
    vanished > "$gone"
    awk -F'\t' -v base="$baseline" -v gone="$(wc -l < "$gone")" -v noise_r="$noise_ratio" -v noise_a="$noise_absolute" "$CSV_AWK"'
        function range(lo, hi) { return lo == hi ? lo : lo " to " hi }
        function add(list, item, sep) { return index(sep list sep, sep item sep) ? list : list (list == "" ? "" : sep) item }
        FILENAME != base && $1 == "unmarked" { unmarked = add(unmarked, $3, ", "); next }
        FILENAME != base { n[$1]++; total++; next }
        FNR == 1 { nb = split_csv($0, bh); for (i = 1; i <= nb; i++) bcol[bh[i]] = i; next }
        {
            split_csv($0, b); rows++
            commits = add(commits, substr(b[bcol["commit"]], 1, 7), ", "); cpus = add(cpus, b[bcol["cpu_model"]], "; ")
            threads = add(threads, b[bcol["threads"]], ", ")
            d = b[bcol["date"]]; if (dlo == "" || d < dlo) dlo = d; if (d > dhi) dhi = d
            l = b[bcol["load_1min"]] + 0; if (rows == 1 || l < llo) llo = l; if (rows == 1 || l > lhi) lhi = l
        }
        END {
            printf "Baseline `%s` (%d figures): commit %s; cpu_model %s; threads %s; %s; load_1min %s.\n\n", base, rows, commits, cpus, threads, range(dlo, dhi), range(llo, lhi)
            printf "Of this run'"'"'s %d figures: **%d worse**, %d better, %d within the noise, %d not comparable", total, n["worse"], n["better"], n["same"], n["n/c"]
            printf " (absolute, another cpu_model or a loaded run), %d without a number on one side, %d new; %d vanished", n["n/a"], n["new"], gone
            printf " (in the baseline, not in this run).\n\n"
            printf "Noise margins: %g%% for a ratio measured within one run (r), %g%% for an absolute time, rate or size (a),\n", noise_r * 100, noise_a * 100
            printf "0 for a machine-independent count (c). Absolute figures compare across runs only on the same cpu_model\n"
            printf "with neither run loaded (1-minute load above the row'"'"'s threads + 1); elsewhere they are n/c, and the\n"
            printf "tables'"'"' baseline column says why.\n\n"
            if (unmarked != "") printf "Not compared (no line in MARKS of bench/report.sh): %s.\n\n", unmarked
        }' "$cmp" "$baseline"
    if grep -q '^worse' "$cmp"; then
        echo "Worse, worst first:"
        echo
        echo "| table | key | figure | baseline | now | new/old |"
        echo "|---|---|---|---|---|---|"
        grep '^worse' "$cmp" | sort -t "$tab" -k2,2gr | awk -F'\t' '{ print "| " $3 " | " $4 " | " $5 " | " $6 " | " $7 " | " $8 " |" }'
        echo
    fi
    if [ -s "$gone" ]; then
        echo "Vanished:"
        echo
        echo "| table | key | figure | baseline |"
        echo "|---|---|---|---|"
        cat "$gone"
        echo
    fi
}

tab=$(printf '\t')
save='' cmp=/dev/null base_in=/dev/null has_base=0 compared=
if [ "$mode" = save ]; then
    [ -d "$(dirname "$baseline")" ] || { echo "report: $baseline: its folder does not exist" >&2; exit 2; }
    save="$baseline.tmp$$"
    trap 'rm -f "$save"' EXIT
    echo "$BASE_HEADER" > "$save"
    printf '%s\n' "$MARKS" | while read -r name rest; do [ -z "$name" ] || table "$name"; done
    figures=$(($(wc -l < "$save") - 1))
    [ "$figures" -gt 0 ] || { echo "report: $dir: no figures to keep as a baseline (no bench CSV there)" >&2; exit 1; }
    mv "$save" "$baseline"
    echo "report: baseline $baseline: $figures figures from $dir"
    exit 0
fi
base_problem="absent"
if [ -f "$baseline" ]; then
    if [ "$(head -n 1 "$baseline")" = "$BASE_HEADER" ]; then has_base=1 base_in=$baseline
    else base_problem="line 1 is not the header $BASE_HEADER"; echo "report: $baseline: $base_problem; nothing compared" >&2
    fi
fi
cmp="$dir/compare.tmp$$" gone="$dir/gone.tmp$$" sum="$dir/summary.tmp$$"
trap 'rm -f "$cmp" "$gone" "$sum" "$md.tmp$$"' EXIT
: > "$cmp"

{
    echo "# shadowlab benchmarks"
    echo
    echo "Written by \`make bench\` (bench/run.sh, bench/report.sh); what each figure means and its target"
    echo "are in bench/README.md. Load at the start and the end of the run:"
    echo
    sed 's/^/    /' "$dir/load.txt" 2>/dev/null || true
    echo
    if [ -s "$dir/steps.txt" ]; then
        echo "Wall time of each step and of each program in it (run.sh's \`steps.txt\`):"
        echo
        sed 's/^/    /' "$dir/steps.txt"
        echo
    fi
    if [ -s "$dir/failures.txt" ]; then
        echo "**Programs that failed** (their tables below are missing or partial; the error is in the run's output):"
        echo
        sed 's/^/    /' "$dir/failures.txt"
        echo
    fi
    echo "## 1. Reference throughput against a bare Embree loop (target ratio >= 0.9)"
    echo
    echo "bare_rays_per_s is the fastest of rtcOccluded1, 4, 8, 16 and rtcOccluded1M (incoherent, coherent), named in fastest:"
    echo
    table reference_throughput.csv scene triangles samples rays fastest bare_rays_per_s reference_rays_per_s ratio occluded1_rays_per_s occluded16_rays_per_s threads load_1min commit
    echo "Seed 002's overhead, single_sample_rt / hard:"
    echo
    table single_sample_overhead.csv scene radius shadow_ratio ray_tracer_ratio threads load_1min commit
    echo "## 2. Against llvmpipe (target speed-up >= 2)"
    echo
    echo "![speed-up over llvmpipe](llvmpipe_depth.svg)"
    echo
    echo "fill_ms is the faster of filling the map's bytes with ordinary stores (store_fill_ms) and with non-temporal ones (stream_fill_ms), the memory-write limit vs_fill (target at 4096^2 <= 2.5) and empty_vs_fill (a render of no triangles) are over:"
    echo
    table llvmpipe_depth.csv scene triangles res llvmpipe_ms shadowlab_ms speedup fill_ms store_fill_ms stream_fill_ms vs_fill empty_ms empty_vs_fill coverage_mismatch depth_mismatch max_depth_diff agree threads load_1min commit
    table llvmpipe_pcf.csv scene width height map_res K llvmpipe_ms shadowlab_ms speedup mae samples_off agree threads load_1min commit
    echo "## 3. Cost growth"
    echo
    echo "Each technique on the scene named in its rows; where it does not handle the scene's light 1, the"
    echo "light column names the light put in its place (bench_lab_open)."
    echo
    echo "![main parameter](growth_main.svg) ![map size](growth_map_size.svg)"
    echo "![triangles](growth_triangles.svg) ![image size](growth_image_width.svg)"
    echo
    table growth.csv technique axis value frame_ms eval_ms build_ms resources_built note light threads load_1min
    echo "Constant time in K with summed-area tables (target: largest K within 1.2x of the smallest):"
    echo
    table constant_time.csv technique settings prefilter K_min K_max frame_min_ms frame_max_ms ratio within light threads load_1min
    echo "Constant in the light's size (the prefiltered PCSS family and occlusion textures claim it; pcss grows):"
    echo
    table light_size.csv technique map_size radius_small radius_large frame_small_ms frame_large_ms ratio within scene threads load_1min
    echo "The same rows' evaluation times (the two radii alternate in every round; a frame also carries its map's build,"
    echo "timed once when built), the texel bytes read per lit candidate (core/counters.h: what the early outs and"
    echo "subdivisions leave to read), and where a technique refused the asked map size (its own cap), why:"
    echo
    table light_size.csv technique map_size settings eval_small_ms eval_large_ms eval_ratio bytes_small bytes_large bytes_ratio note
    echo "Machine-independent work per technique (core/counters.h), beside the hand count where one is known:"
    echo
    table work.csv technique texel_fetches_per_sample rays_per_sample frame_triangles frame_fragments frame_bytes_built hand_rule agrees light
    echo "## 4. Sweep reuse (target <= 1.1; cached references not retraced)"
    echo
    table sweep_reuse.csv sweep technique points sweep_ms one_build_ms evals_ms ratio builds reuses within threads load_1min
    echo "## 5. Thread scaling (target >= 1.8 at 2 threads; the reference >= 0.9 of bare Embree's own scaling)"
    echo
    echo "![thread speed-ups](threads_eval.svg)"
    echo
    table reference_scaling.csv scene rays threads bare_ms_1 bare_ms_n bare_speedup reference_ms_1 reference_ms_n reference_speedup ratio within load_1min
    table raster_threads.csv scene triangles res threads ms_1 ms_n speedup load_1min
    table coherence.csv kib handover_ns own_ns_per_line other_ns_per_line other_over_own load_1min
    echo "The machine's own bound on the speed-ups above and below (cpu_speed.c: fixed loops on each CPU alone and"
    echo "all at once, before the rasterizer's curve and after the techniques'); a speed-up reads against it:"
    echo
    table cpu_speed.csv label loop cpu alone_ms together_ms alone_over_median together_over_alone dynamic_bound static_bound load_1min
    table threads_eval.csv technique threads ms_1 ms_n speedup machine_speedup over_machine cpu_ms_1 cpu_ms_n cpu_bound light width height load_1min
    echo "## 6. Peak memory, 4096^2 maps (target <= 1.2)"
    echo
    table memory.csv technique map_res peak_rss_mib resources_mib ratio within baseline_rss_mib note light load_1min
    echo "## 7. Start-up (target: no OpenImageIO, first line under 20 ms)"
    echo
    table startup.csv command first_line_ms exit_ms loads_openimageio within load_1min
    echo "## 8. Geometry (issue 14): silhouette extraction against triangles; shadow volumes against sm and hard"
    echo
    table silhouette.csv segments triangles silhouette_edges build_ms ns_per_triangle ns_per_triangle_over_smallest threads load_1min
    table volumes.csv scene triangles versus map_size shadow_volume_ms other_ms ratio threads load_1min commit
    echo "view_sample_mapping against the Embree reference at 256 light samples on the same view, and its frame time"
    echo "per (caster triangle, lit candidate) pair against the ball's triangles:"
    echo
    table vsm_reference.csv scene triangles width height samples vsm_ms reference_ms ratio threads load_1min commit
    table vsm_triangles.csv scene segments triangles lit_candidates influence_pairs pairs_over_triangles_samples frame_ms ns_per_pair ns_per_pair_over_smallest ns_per_added_pair threads load_1min
    echo "## 9. Cost against one axis (issue 15) and error against time at pcss's penumbra RMSE (issue 16)"
    echo
    echo "Per lit candidate per unit of the axis, over the first value's (linear: near 1); ratios are medians of per-round ratios:"
    echo
    echo "![cost per unit](sweep.svg)"
    echo
    table sweep.csv technique axis value settings frame_ms eval_ms eval_ns_per_sample eval_ns_per_sample_per_value frame_ratio eval_ratio frame_per_value_ratio per_value_ratio threads load_1min
    echo "Each technique's penumbra RMSE against frame time over map sizes (plots: one per scene):"
    echo
    [ -f "$dir/matched_curve.csv" ] &&
        for s in $(column "$dir/matched_curve.csv" scene | sort -u); do echo "![$s](matched_$s.svg)"; done
    echo
    table matched_curve.csv technique scene map_size penumbra_rmse penumbra_noise_rms penumbra_samples frame_ms eval_ms note threads load_1min
    echo "The frame time each needs at pcss's penumbra RMSE (pcss at its defaults), over pcss's (reached: interpolated"
    echo "in log-log on the curve, at_first_point: already below it at 64^2, an upper bound; no: not reached):"
    echo
    table matched.csv technique scene target_rmse pcss_frame_ms frame_at_target_ms ratio pcss_eval_ms eval_at_target_ms eval_ratio reached note threads load_1min
} > "$md"
# The summary goes above the first section, once every table has compared its figures.
summary > "$sum"
awk -v sum="$sum" '!done && /^## / { while ((getline l < sum) > 0) print l; done = 1 } { print }' "$md" > "$md.tmp$$"
mv "$md.tmp$$" "$md"
plots
echo "report: $md"
