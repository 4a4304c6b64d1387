#!/usr/bin/env bash
# Fracture latency while rendering: rubble-demo's autopilot on the thesis's world.cfg (the seed scene) at
# 1280x720, headless EGL (llvmpipe), with --fire-rate cannon shells at the standing objects and results adopted
# as soon as they are ready (--adopt-ready), so that report.json's latency_ms (impact -> adopted) measures the
# workers, not the deterministic 2-frame delay. Configurations alternate within each round: the fracture
# workers at niceness 0 (before), at -10 (--worker-nice), at -10 with frames waiting up to 8 ms before drawing
# for a job in flight (--adopt-wait), and llvmpipe with one rasteriser thread (--raster-threads 1). One row
# per run in bench/results/latency.csv, then latency.png.
# Usage: scripts/latency-bench.sh BUILD_DIR [SECONDS] [ROUNDS] [CONFIG...]
#   CONFIG is LABEL=OPTIONS (e.g. 'nice-5=--worker-nice -5'); without any, the three above.
# RUBBLE_SEED_MEDIA overrides ../shared/seed/media; RUBBLE_BENCH_RESULTS the output folder.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:?usage: scripts/latency-bench.sh BUILD_DIR [SECONDS] [ROUNDS] [CONFIG...]}"
seconds="${2:-15}"
rounds="${3:-2}"
shift $(($# < 3 ? $# : 3))
configs=("$@")
[ ${#configs[@]} -gt 0 ] ||
    configs=("before=--worker-nice 0 --adopt-wait 0" "nice-10=--worker-nice -10 --adopt-wait 0"
        "nice-10+wait-8=--worker-nice -10 --adopt-wait 8" "raster-1=--worker-nice 0 --adopt-wait 0 --raster-threads 1")
demo="$build/bin/rubble-demo"
[ -x "$demo" ] || { echo "latency-bench: $demo not found (build rubble-demo first)" >&2; exit 1; }
media="${RUBBLE_SEED_MEDIA:-$root/../shared/seed/media}"
scene="$media/world.cfg"
[ -f "$scene" ] || { echo "latency-bench: $scene not found: skipped (the thesis's scenes are not part of the repository)"; exit 0; }
results="${RUBBLE_BENCH_RESULTS:-$root/bench/results}"
mkdir -p "$results"
csv="$results/latency.csv"
[ -f "$csv" ] || echo "date_utc,label,options,scene,seconds,frames,fps_p50,fps_p99,frame_ms_p50,frame_ms_p99,shots,fractures,latency_count,latency_p50_ms,latency_p99_ms,latency_max_ms,worker_nice,workers_at_nice,raster_threads,demo_cpu_ms_per_frame,own_cpu_cores,other_cpu_cores,command" >"$csv"
work=$(mktemp -d /tmp/rubble-latency.XXXXXX)
trap 'rm -rf "$work"' EXIT
. "$root/scripts/bench-configs.sh"

for ((r = 1; r <= rounds; ++r)); do
    for config in "${configs[@]}"; do
        split_config "$config"
        args=(--scene "$scene" --autopilot "$seconds" --fire-rate 5 --adopt-ready --headless --width 1280
            --height 720 --out "$work/run" "${opts[@]}")
        rm -rf "$work/run"
        b0=$(busy)
        t0=$(date +%s.%N)
        env -u DISPLAY /usr/bin/time -f '%U %S' -o "$work/time" "$demo" "${args[@]}" >"$work/log" 2>&1 ||
            { tail -n 20 "$work/log"; exit 1; }
        t1=$(date +%s.%N)
        b1=$(busy)
        python3 - "$work/run/report.json" "$work/time" "$csv" "$label" "${config#*=}" "$t0" "$t1" "$b0" "$b1" \
            "$hz" "rubble-demo ${args[*]/#$work\/run/OUT}" <<'PY'
import json, sys, datetime
rep, timef, csv, label, opts, t0, t1, b0, b1, hz, cmd = sys.argv[1:]
r = json.load(open(rep))
user, system = map(float, open(timef).read().split()[-2:])
wall = float(t1) - float(t0)
own = (user + system) / wall
machine = (int(b1) - int(b0)) / float(hz) / wall
lat, th = r["latency_ms"], r["threads"]
row = [datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"), label, opts,
       "seed:world.cfg", r["sim_seconds"], r["frames"], "%.1f" % r["fps"]["p50"], "%.1f" % r["fps"]["p99"],
       "%.1f" % r["frame_ms"]["p50"], "%.1f" % r["frame_ms"]["p99"], r["shots"], r["fractures"], lat["count"],
       "%.1f" % lat["p50"], "%.1f" % lat["p99"], "%.1f" % lat["max"], th["worker_nice"], th["workers_at_nice"],
       th["raster_threads"], "%.2f" % (1000 * (user + system) / r["frames"]), "%.2f" % own,
       "%.2f" % max(0.0, machine - own), '"' + cmd + '"']
open(csv, "a").write(",".join(str(x) for x in row) + "\n")
print("latency-bench:", ",".join(str(x) for x in row[:-1]))
PY
    done
done
if command -v gnuplot >/dev/null; then
    (cd "$results" && gnuplot -e "csv='latency.csv'; png='latency.png'" "$root/bench/results/latency.gp")
    echo "wrote $csv and ${csv%.csv}.png"
fi
