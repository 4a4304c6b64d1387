#!/usr/bin/env bash
# Headless end-to-end run of rubble-demo (no X server: EGL surfaceless + FBO): the autopilot flies and shoots
# with fixed 1/60 s steps, writes PNGs and the JSON/CSV report. Two runs give pixel-identical screenshots.
# When the thesis's media folder is present, its world.cfg, performance_test.cfg and cube_test.cfg must load
# as they are (missing fighter.3ds and grid.jpg become warnings with stand-ins).
# With rubble-bench, the demo also hosts loopback multiplayer for a client process that must follow it.
# Usage: autopilot_e2e.sh PATH/TO/rubble-demo [PATH/TO/rubble-bench]
set -uo pipefail
demo=${1:?usage: autopilot_e2e.sh PATH/TO/rubble-demo [PATH/TO/rubble-bench]}
bench=${2:-}
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d /tmp/rubble-autopilot.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() {
    echo "FAIL: $*"
    tail -n 20 "$work"/*.log 2>/dev/null
    exit 1
}
run() { # run NAME ARGS...
    local name=$1
    shift
    env -u DISPLAY timeout 300 "$demo" --headless --no-panel "$@" --out "$work/$name" >"$work/$name.log" 2>&1 ||
        fail "$name: rubble-demo exited with $?"
}

run a --scene "$here/e2e.cfg" --autopilot 2 --screenshot-every 1 --record "$work/a.rjournal"
run b --scene "$here/e2e.cfg" --autopilot 2 --screenshot-every 1
for f in report.json frames.csv shot_0001.png shot_0002.png; do
    [ -s "$work/a/$f" ] || fail "missing $f"
done
grep -q '"fps"' "$work/a/report.json" || fail "report.json has no fps"
grep -q '"latency_ms"' "$work/a/report.json" || fail "report.json has no latency"
[ "$(wc -l <"$work/a/frames.csv")" -eq 121 ] || fail "frames.csv should have 120 frames"
cmp -s "$work/a/shot_0002.png" "$work/b/shot_0002.png" || fail "fixed-step runs are not pixel-identical"
[ "$(head -c 4 "$work/a.rjournal")" = RBJL ] || fail "--record wrote no journal"
events=$(sed -n 's/^journal: .* (\([0-9]*\) events, [0-9]* bytes).*$/\1/p' "$work/a.log")
[ -n "$events" ] && [ "$events" -gt 0 ] || fail "the journal has no events: $(grep journal "$work/a.log")"
# A deterministic session's journal replays to the geometry the session ended with.
run c --scene "$here/e2e.cfg" --autopilot 2 --deterministic --record "$work/c.rjournal"
run replay --scene "$here/e2e.cfg" --deterministic --replay "$work/c.rjournal"
recorded=$(sed -n 's/^journal: .*geometry hash \([0-9a-f]*\)$/\1/p' "$work/c.log")
replayed=$(sed -n 's/^replay: .*geometry hash \([0-9a-f]*\)$/\1/p' "$work/replay.log")
[ -n "$recorded" ] && [ "$recorded" = "$replayed" ] || fail "replayed geometry $replayed differs from recorded $recorded"
events=$(sed -n 's/^journal: .* (\([0-9]*\) events, [0-9]* bytes).*$/\1/p' "$work/c.log")
[ -n "$events" ] && [ "$events" -gt 0 ] || fail "the deterministic session journaled nothing"
echo "ok: --record and --replay ($events events, geometry hash $recorded)"

# A latency run: --fire-rate shells (the autopilot holding its own fire), results adopted when ready, the
# fracture workers at the asked niceness (1: any user may lower a thread's priority), llvmpipe yielding while
# jobs run; each fracture is visible on the first frame presented after its adoption.
run latency --scene "$here/e2e.cfg" --autopilot 2 --hold-fire --fire-rate 4 --adopt-ready --worker-nice 1 \
    --raster-yield 1
python3 - "$work/latency/report.json" <<'PY' || fail "the latency run's report: $(cat "$work/latency/report.json")"
import json, sys
r = json.load(open(sys.argv[1]))
t = r["threads"]
assert r["weapons"]["cannon"]["shots"] == 4 and r["shots"] == 4, r["weapons"]  # game frames 60, 75, 90, 105
assert r["fractures"] > 0 and r["latency_ms"]["count"] > 0, (r["fractures"], r["latency_ms"])
assert t["adopt_ready"] and t["worker_nice"] == 1, t
assert 1 <= t["workers_at_nice"] <= t["fracture_workers"] and t["workers_refused"] == 0, t  # those that ran jobs
assert 0 < t["jobs_cpu_ms"] and 0 < t["jobs_busy_ms"], t
assert 0 < t["yielded_frames"] < r["frames"], t  # llvmpipe yields while a job is in flight, not always
# impact -> visible: every adopted fracture is on a presented frame, later than its adoption
v, a = r["visible_ms"], r["latency_ms"]
assert v["count"] == a["count"] and v["p50"] >= a["p50"] and v["p99"] >= a["p99"], (v, a)
rows = [l.split(",") for l in open(sys.argv[1].replace("report.json", "visible.csv")).read().split()[1:]]
assert len(rows) == a["count"], len(rows)
assert all(float(s) > 0 and abs(float(ad) + float(s) - float(vis)) < 0.01 for _, _, ad, s, vis in rows), rows
PY
echo "ok: --fire-rate, --adopt-ready, --worker-nice and --raster-yield"

# --host: a client process (rubble-bench netplay-client) follows the demo over ENet on 127.0.0.1.
if [ -n "$bench" ]; then
    port=$(python3 -c "import socket; s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(('127.0.0.1', 0)); print(s.getsockname()[1])")
    "$bench" netplay-client --port "$port" --seconds 120 >"$work/client.json" 2>"$work/client.err" &
    client=$!
    run host --scene "$here/e2e.cfg" --autopilot 4 --deterministic --host "$port" --host-wait 3
    wait "$client" || fail "the client failed: $(cat "$work/client.json" "$work/client.err")"
    python3 - "$work/client.json" "$work/host.log" <<'PY' || fail "the client did not follow the host: $(cat "$work/client.json")"
import json, re, sys
c = json.load(open(sys.argv[1]))
log = open(sys.argv[2]).read()
h = re.search(r"host: (\d+) clients joined, (\d+) syncs sent, (\d+) acknowledged, (\d+) mismatched", log)
assert c["joined"] and c["syncs"] > 100 and c["events"] > 0, c
assert c["mismatched_hashes"] == 0, c
assert h and int(h.group(1)) == 1 and int(h.group(4)) == 0, log[-400:]
print("ok: --host: the client checked %d syncs and %d events, 0 mismatched hashes" % (c["syncs"], c["events"]))
PY
fi
echo "ok: headless autopilot, report and deterministic screenshots"

# Render quality: both levels draw a picture and the report names the level, the renderer and the internal
# resolution. Dynamic resolution under an unreachable target falls to its floor (2/3 per axis) and no lower.
run gpu --scene "$here/e2e.cfg" --autopilot 1 --screenshot-every 1 --quality gpu --width 480 --height 270
run soft --scene "$here/e2e.cfg" --autopilot 1 --screenshot-every 1 --quality software --width 480 --height 270
run drs --scene "$here/e2e.cfg" --autopilot 1 --quality software --min-scale 0.667 --target-fps 1000 \
    --width 480 --height 270
python3 - "$work" "$here/png_stats.py" <<'PY' || fail "render quality levels"
import json, subprocess, sys
work = sys.argv[1]
for name, quality, shadows in (("gpu", "gpu", True), ("soft", "software", False)):
    r = json.load(open(f"{work}/{name}/report.json"))
    assert r["quality"] == quality and r["shadows"] == shadows, (name, r["quality"], r["shadows"])
    assert r["renderer"], r
    ir = r["internal_resolution"]
    assert (ir["width_p50"], ir["height_p50"]) == (480, 270), ir
    out = subprocess.run([sys.executable, sys.argv[2], f"{work}/{name}/shot_0001.png"], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    var = float(out.stdout.split("var=")[1].split()[0])
    assert var > 50, (name, "blank picture", out.stdout)
r = json.load(open(f"{work}/drs/report.json"))
ir = r["internal_resolution"]
assert (ir["width_min"], ir["height_min"]) == (320, 180), ir  # 2/3 of 480x270, even sizes
assert ir["width_p50"] < 480, ir
print("ok: gpu and software quality render; dynamic resolution floors at %dx%d" % (ir["width_min"], ir["height_min"]))
PY

media=${RUBBLE_SEED_MEDIA:-$here/../../../shared/seed/media}
if [ -d "$media" ]; then
    for cfg in world performance_test cube_test; do
        run "seed_$cfg" --scene "$media/$cfg.cfg" --autopilot 1
        grep -q "fighter.3ds" "$work/seed_$cfg.log" || fail "$cfg: no warning for the missing fighter.3ds"
        grep -q "grid.jpg" "$work/seed_$cfg.log" || fail "$cfg: no warning for the missing grid.jpg"
    done
    echo "ok: the seed's world.cfg, performance_test.cfg and cube_test.cfg load unchanged"
else
    echo "note: seed media not found at $media; seed scenes not checked"
fi
echo "PASS"
