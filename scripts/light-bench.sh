#!/usr/bin/env bash
# Light debris against retirement in one sitting: `rubble-bench scene demolition.cfg --pattern shatter` at
# 10 shots/s for SECONDS (default 60), paced at 60 Hz, alternating --light-per-awake 0 (moving pieces over the
# awake budget retire, the behaviour before) and the runtime's default (they stop colliding with moving
# bodies instead), RUNS times each (default 1) on seeds 1, 2, ...; one row per run in
# bench/results/demolition_light.csv and demolition_light.png. Compare rows of the same seed: other_cpu_cores
# says how much else ran meanwhile.
# Usage: scripts/light-bench.sh BUILD_DIR [SECONDS] [RUNS]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/scripts/bench-lib.sh"
build="${1:?usage: scripts/light-bench.sh BUILD_DIR [SECONDS] [RUNS]}"
seconds="${2:-60}"
runs="${3:-1}"
bench="$build/bin/rubble-bench"
need_binary light-bench "$bench"
csv="$results/demolition_light.csv"
echo "mode,light_per_awake,seed,seconds,frame_p50_ms,frame_p99_ms,physics_p50_ms,physics_p99_ms,fractures,pieces_alive,awake_pieces,light_pieces,frozen_pieces,pieces_made_light,retired_awake,retired_dust,latency_p50_ms,own_cpu_cores,other_cpu_cores" >"$csv"
for ((r = 1; r <= runs; ++r)); do
    for mode in retire light; do
        opts=()
        [ "$mode" = retire ] && opts=(--light-per-awake 0)
        echo "== seed $r: $mode"
        "$bench" scene "$root/assets/scenes/demolition.cfg" --seconds "$seconds" --shots-per-second 10 \
            --pattern shatter --seed "$r" --json "${opts[@]}" |
            python3 -c '
import json, sys
j = json.load(sys.stdin)
mode, seed, secs = sys.argv[1:4]
row = [mode, j["debris_budget"]["light_per_awake"], seed, secs, j["frame_ms"]["p50"], j["frame_ms"]["p99"],
       j["physics_ms"]["p50"], j["physics_ms"]["p99"], j["fractures"], j["pieces_alive"], j["awake_pieces"],
       j["light_pieces"], j["frozen_pieces"], j["pieces_light"], j["retired_by"]["awake_budget"],
       j["retired_by"]["dust"], j["latency_ms"]["p50"], j["cpu_cores"]["own"], j["cpu_cores"]["other"]]
print(",".join(str(round(v, 3)) if isinstance(v, float) else str(v) for v in row))' "$mode" "$r" "$seconds" |
            tee -a "$csv"
    done
done
(cd "$results" && gnuplot -e "csv='demolition_light.csv'; png='demolition_light.png'" "$root/bench/results/demolition_light.gp")
echo "wrote $csv and ${csv%.csv}.png"
