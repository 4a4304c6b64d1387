#!/usr/bin/env bash
# The pile at rest and capped hulls in one sitting: `rubble-bench scene demolition.cfg --pattern shatter` at 10
# shots/s for SECONDS (default 60), paced at 60 Hz, alternating the configurations "after" (this build),
# "cap16" (this build, --max-hull-points 16) and, when RUBBLE_BEFORE_BENCH names another rubble-bench binary,
# "before" (that binary), RUNS times each (default 1) on seeds 1, 2, ...; one row per run in
# bench/results/demolition_rest.csv and demolition_rest.png. other_cpu_cores says how much else ran meanwhile.
# Usage: [RUBBLE_BEFORE_BENCH=BIN] scripts/rest-bench.sh BUILD_DIR [SECONDS] [RUNS]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/scripts/bench-lib.sh"
build="${1:?usage: scripts/rest-bench.sh BUILD_DIR [SECONDS] [RUNS]}"
seconds="${2:-60}"
runs="${3:-1}"
bench="$build/bin/rubble-bench"
need_binary rest-bench "$bench"
csv="$results/demolition_rest.csv"
[ -f "$csv" ] || echo "date_utc,label,seed,seconds,frame_p50_ms,frame_p99_ms,physics_p50_ms,physics_p99_ms,fractures,pieces_alive,awake_pieces,light_pieces,frozen_pieces,pieces_woken,retired_awake,retired_dust,own_cpu_cores,other_cpu_cores" >"$csv"
labels=(after cap16)
[ -z "${RUBBLE_BEFORE_BENCH:-}" ] || labels=(before after cap16)
for ((r = 1; r <= runs; ++r)); do
    for label in "${labels[@]}"; do
        bin="$bench"
        opts=()
        [ "$label" = before ] && bin="$RUBBLE_BEFORE_BENCH"
        [ "$label" = cap16 ] && opts=(--max-hull-points 16)
        echo "== seed $r: $label"
        "$bin" scene "$root/assets/scenes/demolition.cfg" --seconds "$seconds" --shots-per-second 10 \
            --pattern shatter --seed "$r" --json "${opts[@]}" |
            python3 -c '
import datetime, json, sys
j = json.load(sys.stdin)
label, seed, secs = sys.argv[1:4]
row = [datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"), label, seed, secs,
       j["frame_ms"]["p50"], j["frame_ms"]["p99"], j["physics_ms"]["p50"], j["physics_ms"]["p99"], j["fractures"],
       j["pieces_alive"], j["awake_pieces"], j["light_pieces"], j["frozen_pieces"], j["pieces_woken"],
       j["retired_by"]["awake_budget"], j["retired_by"]["dust"], j["cpu_cores"]["own"], j["cpu_cores"]["other"]]
print(",".join(str(round(v, 3)) if isinstance(v, float) else str(v) for v in row))' "$label" "$r" "$seconds" |
            tee -a "$csv"
    done
done
(cd "$results" && gnuplot -e "csv='demolition_rest.csv'; png='demolition_rest.png'" "$root/bench/results/demolition_rest.gp")
echo "wrote $csv and ${csv%.csv}.png"
