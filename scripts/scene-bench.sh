#!/usr/bin/env bash
# The scene table of bench/results: every shipped scene (and the thesis's own scenes when ../shared/seed/media
# is present) run by `rubble-bench scene` for SECONDS (default 60) at 10 shots/s with the default worker count,
# paced at 60 Hz with idle adoption; one row each in a fresh scene.csv, then scene.png (bench/results/scene.gp).
# The demolition scenes (assets/scenes/demolition*.cfg) run the same way with --pattern shatter; their frames
# are summarised per half second in demolition_frames.csv and drawn over time in demolition.png; demolition.cfg
# runs again with the stress solver on (--structure, bearings), as the demo plays it. A last row
# is the stretch toward 20,000 pieces at 30 fps: the 500k scene for 2.5 x SECONDS at 25 shots/s of 32 cells,
# with the debris budgets of a 30 Hz frame (1,500 awake bodies, a 16 ms physics step).
# Usage: scripts/scene-bench.sh BUILD_DIR [SECONDS]
# RUBBLE_BENCH_RESULTS=DIR writes somewhere else than bench/results/; RUBBLE_SEED_MEDIA overrides the seed
# media folder. Each row's other_cpu_cores says how much else ran meanwhile: re-run rows where it is not ~0.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/scripts/bench-lib.sh"
build="${1:?usage: scripts/scene-bench.sh BUILD_DIR [SECONDS]}"
seconds="${2:-60}"
bench="$build/bin/rubble-bench"
need_binary scene-bench "$bench" "make release"

scenes=("$root/assets/scenes/cube_test.cfg" "$root/assets/scenes/cube_test_10092.cfg"
        "$root/assets/scenes/performance_test.cfg")
for s in cube_test.cfg performance_test.cfg world.cfg; do
    if [ -f "$media/$s" ]; then
        scenes+=("$(cd "$media" && pwd)/$s")
    else
        echo "scene-bench: $media/$s not found: skipped (the thesis's scenes are not part of the repository)"
    fi
done

csv="$results/scene.csv"
frames="$results/demolition_frames.csv"
rm -f "$csv" "$frames"
run() { # scene, extra options... (RUN_SECONDS, RUN_RATE and RUN_TAG override the length, the shot rate, the name)
    local s=$1
    shift
    local secs="${RUN_SECONDS:-$seconds}" rate="${RUN_RATE:-10}"
    echo "== $s ($secs s, $rate shots/s) $*"
    # the row names the scene relative to the repository (or seed: for the thesis's own)
    name="${s#"$root/"}"
    case "$s" in "$root"/*) ;; *) name="seed:$(basename "$s")" ;; esac
    name="$name${RUN_TAG:-}"
    tmp="$results/.scene-row.csv"
    rm -f "$tmp" "$tmp.frames"
    "$bench" scene "$s" --seconds "$secs" --shots-per-second "$rate" --append-csv "$tmp" --frames-csv "$tmp.frames" "$@"
    [ -f "$csv" ] || head -n 1 "$tmp" >"$csv"
    tail -n +2 "$tmp" | sed "s#^[^,]*#$name#" >>"$csv"
    if [ "$*" != "" ]; then # per half second: worst and mean frame, worst physics step, pieces at its end
        [ -f "$frames" ] || echo "scene,second,frame_max_ms,frame_mean_ms,physics_max_ms,pieces_alive,awake_pieces,frozen_pieces" >"$frames"
        awk -F, -v name="$name" 'NR > 1 {
            w = int($1 / 30); if (!(w in n)) order[++k] = w
            n[w]++; sum[w] += $2; if ($2 > mx[w]) mx[w] = $2; if ($3 > ph[w]) ph[w] = $3
            alive[w] = $7; awake[w] = $8; frozen[w] = $9 }
            END { for (i = 1; i <= k; i++) { w = order[i]
                printf "%s,%.1f,%.3f,%.3f,%.3f,%d,%d,%d\n", name, (w + 1) * 0.5, mx[w], sum[w] / n[w], ph[w], alive[w], awake[w], frozen[w] } }' \
            "$tmp.frames" >>"$frames"
    fi
    rm -f "$tmp" "$tmp.frames"
}
for s in "${scenes[@]}"; do
    run "$s"
done
for s in demolition.cfg demolition_block.cfg; do
    run "$root/assets/scenes/$s" --pattern shatter
done
RUN_TAG=" (structure)" run "$root/assets/scenes/demolition.cfg" --pattern shatter --structure
RUN_SECONDS=$((5 * seconds / 2)) RUN_RATE=25 RUN_TAG=" (stretch)" run "$root/assets/scenes/demolition_block.cfg" \
    --pattern shatter --cells 32 --max-awake 1500 --physics-budget-ms 16
echo "CSV: $csv, $frames"
if command -v gnuplot >/dev/null 2>&1; then
    type="$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' "$build/CMakeCache.txt" 2>/dev/null)"
    (cd "$results" && gnuplot -e "build='${type:-Release}'" "$root/bench/results/scene.gp" &&
        gnuplot -e "build='${type:-Release}'" "$root/bench/results/demolition.gp") &&
        echo "plots: $results/scene.png, $results/demolition.png"
else
    echo "scene-bench: no gnuplot: scene.png not redrawn"
fi
