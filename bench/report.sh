#!/bin/sh
# report.sh -- reports/bench/README.md from the CSVs run.sh wrote: one table
# per bench (the columns that carry the figures, then threads, load and
# commit), the programs that failed (failures.txt), and gnuplot plots (SVG
# and PNG, with their .gp scripts and .dat data): llvmpipe speed-ups against
# map size, cost growth per axis, and the thread-scaling curves per technique
# beside bare Embree's, each with its target or ideal drawn in.
# Usage: bench/report.sh DIR
set -eu
dir=${1:-reports/bench}
md="$dir/README.md"

# table CSV COLUMNS...: a markdown table of the named columns of CSV.
table() {
    f="$dir/$1"; name=$1; shift
    [ -f "$f" ] || { echo "(not run: $name missing)"; echo; return; }
    awk -F, -v cols="$*" '
        function split_csv(line, out,    n, i, c, q, field) {
            n = 0; field = ""; q = 0
            for (i = 1; i <= length(line); i++) {
                c = substr(line, i, 1)
                if (c == "\"") { q = !q; continue }
                if (c == "," && !q) { out[++n] = field; field = ""; continue }
                field = field c
            }
            out[++n] = field
            return n
        }
        NR == 1 {
            n = split_csv($0, head); m = split(cols, want, " ")
            for (k = 1; k <= m; k++) for (i = 1; i <= n; i++) if (head[i] == want[k]) idx[k] = i
            line = "|"; sep = "|"
            for (k = 1; k <= m; k++) { line = line " " want[k] " |"; sep = sep "---|" }
            print line; print sep; next
        }
        {
            split_csv($0, f); line = "|"
            for (k = 1; k <= m; k++) line = line " " f[idx[k]] " |"
            print line
        }' "$f"
    echo
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

{
    echo "# shadowlab benchmarks"
    echo
    echo "Written by \`make bench\` (bench/run.sh, bench/report.sh); what each figure means and its target"
    echo "are in bench/README.md. Load at the start and the end of the run:"
    echo
    sed 's/^/    /' "$dir/load.txt" 2>/dev/null || true
    echo
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
    table llvmpipe_depth.csv scene triangles res llvmpipe_ms shadowlab_ms speedup fill_ms vs_fill coverage_mismatch depth_mismatch max_depth_diff agree threads load_1min commit
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
    table threads_eval.csv technique threads ms_1 ms_n speedup light width height load_1min
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
    table vsm_triangles.csv segments triangles lit_candidates frame_ms ns_per_triangle_sample ns_per_triangle_sample_over_smallest threads load_1min
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
plots
echo "report: $md"
