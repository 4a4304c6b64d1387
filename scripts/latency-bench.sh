#!/usr/bin/env bash
# Fracture latency while rendering: rubble-demo's autopilot on the thesis's world.cfg (the seed scene) at
# 1280x720, headless EGL (llvmpipe), with --fire-rate cannon shells at the objects and large pieces and results adopted
# as soon as they are ready (--adopt-ready), so that report.json's latency_ms (impact -> adopted) measures the
# workers, not the deterministic 2-frame delay; visible_ms adds the wait for the frame that shows the pieces.
# Configurations alternate within each round: the demo's defaults (workers at niceness -5, hardware threads
# - 1 of them: one on 2 cores), two workers (a blast's objects cut two at a time), and two workers with
# llvmpipe's rasteriser threads yielding (niceness 10) while a job is in flight. One row per run in bench/results/latency.csv (then latency.png), and
# one row per stage and run in latency_stages.csv: queue, the worker's stages, handoff, adoption and the
# frame that shows the pieces (shown), with p50, p99, the mean over the slowest tenth of the jobs (impact ->
# visible) and the stage's value in the job at the visible p99.
# Usage: scripts/latency-bench.sh BUILD_DIR [SECONDS] [ROUNDS] [CONFIG...]
#   CONFIG is LABEL=OPTIONS (e.g. 'nice-10=--worker-nice -10'); without any, the three above.
# RUBBLE_SEED_MEDIA overrides ../shared/seed/media; RUBBLE_BENCH_RESULTS the output folder.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/scripts/bench-lib.sh"
build="${1:?usage: scripts/latency-bench.sh BUILD_DIR [SECONDS] [ROUNDS] [CONFIG...]}"
seconds="${2:-15}"
rounds="${3:-2}"
shift $(($# < 3 ? $# : 3))
configs=("$@")
[ ${#configs[@]} -gt 0 ] ||
    configs=("default=--workers -1" "workers-2=--workers 2" "workers-2+yield-10=--workers 2 --raster-yield 10")
demo="$build/bin/rubble-demo"
need_binary latency-bench "$demo"
scene="$media/world.cfg"
need_media latency-bench "$scene"
csv="$results/latency.csv"
[ -f "$csv" ] || echo "date_utc,label,options,scene,seconds,frames,fps_p50,fps_p99,frame_ms_p50,frame_ms_p99,shots,fractures,latency_count,latency_p50_ms,latency_p99_ms,latency_max_ms,worker_nice,workers_at_nice,raster_threads,demo_cpu_ms_per_frame,own_cpu_cores,other_cpu_cores,command,visible_p50_ms,visible_p99_ms,job_cpu_share" >"$csv"
stages="$results/latency_stages.csv"
[ -f "$stages" ] || echo "date_utc,label,options,stage,p50_ms,p99_ms,tail_mean_ms,at_p99_ms,tail_count,other_cpu_cores" >"$stages"
work=$(mktemp -d /tmp/rubble-latency.XXXXXX)
trap 'rm -rf "$work"' EXIT

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
            "$hz" "rubble-demo ${args[*]/#$work\/run/OUT}" "$stages" <<'PY'
import csv as csvmod, json, math, os, sys, datetime
rep, timef, csv, label, opts, t0, t1, b0, b1, hz, cmd, stagescsv = sys.argv[1:]
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
       "%.2f" % max(0.0, machine - own), '"' + cmd + '"', "%.1f" % r["visible_ms"]["p50"],
       "%.1f" % r["visible_ms"]["p99"], "%.2f" % (th["jobs_cpu_ms"] / max(th["jobs_busy_ms"], 1e-9))]
open(csv, "a").write(",".join(str(x) for x in row) + "\n")
print("latency-bench:", ",".join(str(x) for x in row[:-4] + row[-3:]))
# Each adopted job's stages (the world's latency.csv) with the frame that showed it (the demo's visible.csv):
# per stage its p50 and p99, its mean over the slowest tenth (impact -> visible) and its value in the job at
# the visible p99.
run = os.path.dirname(rep)
shown = {(v["object"], v["frame"]): v for v in csvmod.DictReader(open(os.path.join(run, "visible.csv")))}
jobs = []
for t in csvmod.DictReader(open(os.path.join(run, "latency.csv"))):
    v = shown.get((t["object"], t["frame"]))
    if v and t["stale"] == "0" and t["failed"] == "0" and t["missed"] == "0":
        jobs.append({**{k[:-3]: float(x) for k, x in t.items() if k.endswith("_ms")},
                     "shown": float(v["shown_ms"]), "visible": float(v["visible_ms"])})
def q(values, p):  # nearest rank, as the demo's report
    v = sorted(values)
    return v[min(len(v) - 1, max(0, math.ceil(p * len(v)) - 1))] if v else 0.0
names = ["queue", "prepare", "cell", "boolean", "islands", "decomposition", "finish", "handoff", "adoption",
         "shown", "total", "visible"]
if jobs:
    cut = q([j["visible"] for j in jobs], 0.9)
    tail = [j for j in jobs if j["visible"] >= cut]
    at99 = min((j for j in jobs if j["visible"] >= q([j["visible"] for j in jobs], 0.99)), key=lambda j: j["visible"])
    with open(stagescsv, "a") as f:
        for n in names:
            vals = [j[n] for j in jobs]
            f.write(",".join([row[0], label, opts, n, "%.1f" % q(vals, 0.5), "%.1f" % q(vals, 0.99),
                              "%.1f" % (sum(j[n] for j in tail) / len(tail)), "%.1f" % at99[n], str(len(tail)),
                              row[21]]) + "\n")
    print("latency-bench: slowest tenth (%d jobs), mean ms: " % len(tail) +
          ", ".join("%s %.1f" % (n, sum(j[n] for j in tail) / len(tail)) for n in names))
PY
    done
done
if command -v gnuplot >/dev/null; then
    (cd "$results" && gnuplot -e "csv='latency.csv'; png='latency.png'" "$root/bench/results/latency.gp")
    echo "wrote $csv and ${csv%.csv}.png"
fi
