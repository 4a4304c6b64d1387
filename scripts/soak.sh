#!/usr/bin/env bash
# Soak run (issue #7): rubble-bench scene with continuous fire for many frames, watching resident memory.
# Usage: scripts/soak.sh [BUILD_DIR=build-release] [FRAMES=100000] [SCENE=assets/scenes/performance_test.cfg]
#        (extra arguments after SCENE go to rubble-bench scene, e.g. --shots-per-second 20 --workers 1)
# Reports resident memory (VmRSS from /proc, sampled every second) at start (first sample after 2 s: the scene
# is loaded and firing), at 10 %, 50 % and the end of the run, the peak (VmHWM), the growth over the second half, and the
# bench's own volume error and counters (with what the long-lived containers hold at the end: bodies, world
# objects, timing records, debris particles, triangles of live objects). The JSON report is kept in a temp dir
# (its path is printed). Exit 1 on a crash, a volume error above 1e-6, or a JSON it cannot read.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-build-release}
frames=${2:-100000}
scene=${3:-assets/scenes/performance_test.cfg}
shift 3 2>/dev/null || shift $#
bench=$dir/bin/rubble-bench
[ -x "$bench" ] || { echo "soak: $bench not found; build it first (make release)" >&2; exit 2; }
out=$(mktemp -d)
echo "soak: $bench scene $scene --frames $frames --shots-per-second ${SOAK_SHOTS:-10} $*"
t0=$(date +%s)
"$bench" scene "$scene" --frames "$frames" --shots-per-second "${SOAK_SHOTS:-10}" --json "$@" \
    >"$out/report.json" 2>"$out/stderr.log" &
pid=$!
: >"$out/rss.txt"
while kill -0 "$pid" 2>/dev/null; do
    rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
    hwm=$(awk '/^VmHWM:/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
    [ -n "$rss" ] && echo "$(($(date +%s) - t0)) $rss $hwm" >>"$out/rss.txt"
    sleep 1
done
status=0
wait "$pid" || status=$?
seconds=$(($(date +%s) - t0))
if [ $status -ne 0 ]; then
    echo "soak: CRASHED (exit $status) after ${seconds}s; stderr:"
    tail -30 "$out/stderr.log"
    exit 1
fi
python3 - "$out/report.json" "$out/rss.txt" "$seconds" <<'PY'
import json, sys
report = json.load(open(sys.argv[1]))
rows = [list(map(int, l.split())) for l in open(sys.argv[2]) if len(l.split()) == 3]
if not rows:
    sys.exit("soak: no memory samples (the run was shorter than a second)")
mb = lambda kb: kb / 1024.0
at = lambda f: mb(rows[min(len(rows) - 1, int(f * (len(rows) - 1)))][1])
# "start": the first sample after two seconds (the scene is loaded and firing has begun).
start = mb(next((r for r in rows if r[0] >= 2), rows[0])[1])
end, peak = mb(rows[-1][1]), max(mb(r[2]) for r in rows)
print(f"soak: {report['frames']} frames in {sys.argv[3]} s, crash-free (report {sys.argv[1]})")
print(f"  resident memory (MB): start {start:.1f}, 10% {at(0.1):.1f}, 50% {at(0.5):.1f}, end {end:.1f}, "
      f"peak {peak:.1f} (bench peak_rss_mb {report.get('peak_rss_mb', float('nan')):.1f}); "
      f"second-half growth {end - at(0.5):+.1f}")
print(f"  shots {report.get('shots')}, impacts {report.get('impacts')}, fractures {report.get('fractures')}, "
      f"pieces alive {report.get('pieces_alive')}, retired {report.get('pieces_retired')}")
print("  at the end: " + ", ".join(f"{k.replace('_', ' ')} {report[k]}" for k in
      ("bodies", "world_objects", "timing_records", "debris_particles", "world_triangles", "world_max_triangles",
       "world_convex_parts") if k in report))
fm = report.get("frame_ms", {})
print(f"  frame ms p50 {fm.get('p50', 0):.3f} p99 {fm.get('p99', 0):.3f} max {fm.get('max', 0):.3f}")
err = report.get("volume_error")
print(f"  volume error {err:.3g} (relative; live + retired + dropped vs start)")
sys.exit(0 if err is not None and err < 1e-6 else 1)
PY
