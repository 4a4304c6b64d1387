#!/usr/bin/env bash
# The showcase's scale and frame cost: `rubble-demo --scene assets/scenes/demolition_block.cfg --showcase
# --demolish 0.5 --autopilot SECONDS --headless --width 640 --height 360` (llvmpipe), one run per CONFIG in
# turn, ROUNDS times. A row per run in bench/results/showcase.csv: pieces live / awake / light / frozen at the
# end, the frame p50 of the last 150 frames against that of the same view before the first blast (frames
# 10-59), and the geometry hash of the run's journal, which equal options must reproduce (the autopilot is
# deterministic). SHOWCASE_KEEP=DIR keeps each run's report and screenshots (--screenshot-every) there.
# Usage: scripts/showcase-bench.sh BUILD_DIR [SECONDS] [ROUNDS] [LABEL=OPTIONS...]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/scripts/bench-lib.sh"
build="${1:?usage: scripts/showcase-bench.sh BUILD_DIR [SECONDS] [ROUNDS] [LABEL=OPTIONS...]}"
seconds="${2:-30}"
rounds="${3:-1}"
shift $(($# < 3 ? $# : 3))
configs=("$@")
[ ${#configs[@]} -gt 0 ] || configs=("default=")
demo="$build/bin/rubble-demo"
need_binary showcase-bench "$demo"
csv="$results/showcase.csv"
[ -f "$csv" ] || echo "date_utc,label,options,sim_seconds,frames,fractures,pieces_created,pieces_live,pieces_awake,pieces_light,pieces_frozen,retired_awake,retired_dust,frame_p50_before_first_blast_ms,frame_p50_last_150_frames_ms,end_over_before,step_p50_last_150_frames_ms,geometry_hash,own_cpu_cores,other_cpu_cores" >"$csv"
work=$(mktemp -d /tmp/rubble-showcase-bench.XXXXXX)
trap 'rm -rf "$work"' EXIT
for ((r = 1; r <= rounds; ++r)); do
    for config in "${configs[@]}"; do
        split_config "$config"
        rm -rf "$work/run"
        b0=$(busy)
        t0=$(date +%s.%N)
        env -u DISPLAY /usr/bin/time -f '%U %S' -o "$work/time" "$demo" --headless --mute \
            --scene "$root/assets/scenes/demolition_block.cfg" --showcase --demolish 0.5 --autopilot "$seconds" \
            --width 640 --height 360 --out "$work/run" --record "$work/run.journal" "${opts[@]}" >"$work/log" 2>&1 ||
            { tail -n 20 "$work/log"; exit 1; }
        t1=$(date +%s.%N)
        b1=$(busy)
        [ -z "${SHOWCASE_KEEP:-}" ] || { mkdir -p "$SHOWCASE_KEEP" && cp -r "$work/run" "$SHOWCASE_KEEP/$label-$r"; }
        hash=$(sed -n 's/.*geometry hash \([0-9a-f]*\).*/\1/p' "$work/log" | tail -n 1)
        python3 - "$work/run" "$work/time" "$csv" "$label" "${config#*=}" "$t0" "$t1" "$b0" "$b1" "$hz" "$hash" <<'PY'
import csv as csvmod, json, statistics, sys, datetime
run, timef, out, label, opts, t0, t1, b0, b1, hz, geometry = sys.argv[1:]
r = json.load(open(run + "/report.json"))
rows = list(csvmod.DictReader(open(run + "/frames.csv")))
before = [float(x["frame_ms"]) for x in rows if 10 <= int(x["frame"]) < 60]
end = rows[-150:]
p50_before = statistics.median(before)
p50_end = statistics.median(float(x["frame_ms"]) for x in end)
user, system = map(float, open(timef).read().split()[-2:])
wall = float(t1) - float(t0)
own = (user + system) / wall
machine = (int(b1) - int(b0)) / float(hz) / wall
by = r["pieces_retired_by"]
row = [datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"), label, opts,
       r["sim_seconds"], r["frames"], r["fractures"], r["pieces_created"], r["pieces_live"], r["pieces_awake"],
       r["pieces_light"], r["pieces_frozen"], by["awake"], by["dust"], "%.1f" % p50_before, "%.1f" % p50_end,
       "%.2f" % (p50_end / p50_before), "%.1f" % statistics.median(float(x["step_ms"]) for x in end), geometry,
       "%.2f" % own, "%.2f" % max(0.0, machine - own)]
open(out, "a").write(",".join(str(x) for x in row) + "\n")
print("showcase-bench:", ",".join(str(x) for x in row))
PY
    done
done
if command -v gnuplot >/dev/null; then
    (cd "$results" && gnuplot -e "csv='showcase.csv'; png='showcase.png'" "$root/bench/results/showcase.gp")
    echo "wrote $csv and ${csv%.csv}.png"
fi
