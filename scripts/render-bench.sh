#!/usr/bin/env bash
# The renderer's frame rate on software OpenGL: rubble-demo's autopilot (shooting) on the thesis's
# performance_test.cfg at 1920x1080 in an Xvfb window (llvmpipe), one row per run appended to
# bench/results/render.csv, then render.png (bench/results/render.gp).
# Usage: scripts/render-bench.sh BUILD_DIR [SECONDS] [LABEL] [demo options...]
# Each row names the renderer, quality, internal resolution, the demo's and Xvfb's CPU time per frame (load
# independent) and other_cpu_cores (the rest of the machine meanwhile): frame rates from rows where it is not ~0
# are a busy machine's. RUBBLE_SEED_MEDIA overrides ../shared/seed/media; RUBBLE_BENCH_RESULTS the output.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/scripts/bench-lib.sh"
build="${1:?usage: scripts/render-bench.sh BUILD_DIR [SECONDS] [LABEL] [demo options...]}"
seconds="${2:-20}"
label="${3:-default}"
shift $(($# < 3 ? $# : 3))
demo="$build/bin/rubble-demo"
need_binary render-bench "$demo"
scene="$media/performance_test.cfg"
need_media render-bench "$scene"
command -v Xvfb >/dev/null || { echo "render-bench: Xvfb missing (apt-get install xvfb)" >&2; exit 1; }
out=$(mktemp -d /tmp/rubble-render.XXXXXX)
xvfb_pid=""
trap '[ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null; rm -rf "$out"' EXIT

disp=""
for n in $(seq 150 199); do
    if [ ! -e "/tmp/.X11-unix/X$n" ] && [ ! -e "/tmp/.X$n-lock" ]; then disp=":$n"; break; fi
done
[ -n "$disp" ] || { echo "render-bench: no free X display" >&2; exit 1; }
Xvfb "$disp" -screen 0 1920x1080x24 -nolisten tcp >/dev/null 2>&1 &
xvfb_pid=$!
for _ in $(seq 1 100); do [ -e "/tmp/.X11-unix/X${disp#:}" ] && break; sleep 0.1; done

ticks() { awk '{print $14 + $15}' "/proc/$1/stat"; }     # utime + stime of a process
cores=$(nproc)
args=(--scene "$scene" --autopilot "$seconds" --window --width 1920 --height 1080 --out "$out/run" "$@")
x0=$(ticks "$xvfb_pid")
b0=$(busy)
t0=$(date +%s.%N)
DISPLAY=$disp /usr/bin/time -f '%U %S' -o "$out/time" "$demo" "${args[@]}" >"$out/log" 2>&1 ||
    { tail -n 20 "$out/log"; exit 1; }
t1=$(date +%s.%N)
b1=$(busy)
x1=$(ticks "$xvfb_pid")
grep '^report:' "$out/log"

csv="$results/render.csv"
[ -f "$csv" ] || echo "date_utc,label,scene,renderer,quality,shadows,output,internal_p50,internal_min,seconds,frames,fps_p50,fps_p99,frame_ms_p50,frame_ms_p99,demo_cpu_ms_per_frame,xvfb_cpu_ms_per_frame,own_cpu_cores,other_cpu_cores,command" >"$csv"
python3 - "$out/run/report.json" "$out/time" "$csv" "$label" "$t0" "$t1" "$b0" "$b1" "$x0" "$x1" "$hz" "$cores" \
    "rubble-demo ${args[*]/#$out\/run/OUT}" <<'PY'
import json, sys, datetime
rep, timef, csv, label, t0, t1, b0, b1, x0, x1, hz, cores, cmd = sys.argv[1:]
r = json.load(open(rep))
u, s = map(float, open(timef).read().split()[-2:])
wall = float(t1) - float(t0)
hz = float(hz)
demo_s = u + s
xvfb_s = (int(x1) - int(x0)) / hz
machine = (int(b1) - int(b0)) / hz / wall
own = (demo_s + xvfb_s) / wall
other = max(0.0, machine - own)
frames = r["frames"]
ir = r["internal_resolution"]
row = [datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"), label,
       "seed:performance_test.cfg", r["renderer"].replace(",", ";"), r["quality"], int(r["shadows"]),
       "%dx%d" % (r["output"]["width"], r["output"]["height"]),
       "%dx%d" % (ir["width_p50"], ir["height_p50"]), "%dx%d" % (ir["width_min"], ir["height_min"]),
       r["sim_seconds"], frames, "%.1f" % r["fps"]["p50"], "%.1f" % r["fps"]["p99"],
       "%.2f" % r["frame_ms"]["p50"], "%.2f" % r["frame_ms"]["p99"], "%.2f" % (1000 * demo_s / frames),
       "%.2f" % (1000 * xvfb_s / frames), "%.2f" % own, "%.2f" % other, '"' + cmd.replace('"', "'") + '"']
open(csv, "a").write(",".join(str(x) for x in row) + "\n")
print("render-bench:", ",".join(str(x) for x in row[:-1]))
PY
if command -v gnuplot >/dev/null && [ -f "$root/bench/results/render.gp" ]; then
    (cd "$results" && gnuplot -e "csv='render.csv'; png='render.png'" "$root/bench/results/render.gp")
fi
