#!/usr/bin/env bash
# The scene table of bench/results: every shipped scene (and the thesis's own scenes when ../shared/seed/media
# is present) run by `rubble-bench scene` for SECONDS (default 60) at 10 shots/s with the default worker count,
# paced at 60 Hz with idle adoption; one row each in a fresh scene.csv, then scene.png (bench/results/scene.gp).
# Usage: scripts/scene-bench.sh BUILD_DIR [SECONDS]
# RUBBLE_BENCH_RESULTS=DIR writes somewhere else than bench/results/; RUBBLE_SEED_MEDIA overrides the seed
# media folder. Each row's other_cpu_cores says how much else ran meanwhile: re-run rows where it is not ~0.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:?usage: scripts/scene-bench.sh BUILD_DIR [SECONDS]}"
seconds="${2:-60}"
bench="$build/bin/rubble-bench"
[ -x "$bench" ] || { echo "scene-bench: $bench not found (build the tree first: make release)" >&2; exit 1; }
results="${RUBBLE_BENCH_RESULTS:-$root/bench/results}"
media="${RUBBLE_SEED_MEDIA:-$root/../shared/seed/media}"
mkdir -p "$results"

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
rm -f "$csv"
for s in "${scenes[@]}"; do
    echo "== $s ($seconds s)"
    # the row names the scene relative to the repository (or seed: for the thesis's own)
    name="${s#"$root/"}"
    case "$s" in "$root"/*) ;; *) name="seed:$(basename "$s")" ;; esac
    tmp="$results/.scene-row.csv"
    rm -f "$tmp"
    "$bench" scene "$s" --seconds "$seconds" --shots-per-second 10 --append-csv "$tmp"
    [ -f "$csv" ] || head -n 1 "$tmp" >"$csv"
    tail -n +2 "$tmp" | sed "s#^[^,]*#$name#" >>"$csv"
    rm -f "$tmp"
done
echo "CSV: $csv"
if command -v gnuplot >/dev/null 2>&1; then
    (cd "$results" && gnuplot "$root/bench/results/scene.gp") &&
        echo "plot: $results/scene.png"
else
    echo "scene-bench: no gnuplot: scene.png not redrawn"
fi
