#!/usr/bin/env bash
# End-to-end loopback multiplayer of rubble-demo with real ENet on 127.0.0.1: a headless host (autopilot,
# --deterministic --host PORT --host-wait 3) and a --join window under Xvfb that joins it late (the host holds
# at 3 s of game time, before the first hit, until it has: snapshot, then live journal events), cuts the
# pieces itself from the host's journal events and draws them at the host's placements.
# Asserts: 0 mismatched geometry hashes on both sides, the client's final geometry hash equals the host's, the
# client drew frames (and its screenshot is not blank), both exit with 0; bad --join addresses are refused.
# Usage: netplay_e2e.sh PATH/TO/rubble-demo      Exit 77 = skipped (Xvfb missing).
set -uo pipefail
demo=${1:?usage: netplay_e2e.sh PATH/TO/rubble-demo}
here=$(cd "$(dirname "$0")" && pwd)
if ! command -v Xvfb >/dev/null; then
    echo "SKIP: Xvfb is not installed (apt-get install xvfb)"
    exit 77
fi
source "$here/../support/e2e.sh" rubble-netplay 30
start_xvfb 191 240 -screen 0 640x360x24

# Refused before any packet is sent: a non-loopback host, a malformed HOST:PORT.
timeout 60 "$demo" --join 10.1.2.3:4000 --width 160 --height 90 >"$work/bad1.log" 2>&1 && fail "a non-loopback host was accepted"
grep -q "not a loopback address" "$work/bad1.log" || fail "no loopback error: $(cat "$work/bad1.log")"
timeout 60 "$demo" --join 127.0.0.1:99999 --width 160 --height 90 >"$work/bad2.log" 2>&1 && fail "port 99999 was accepted"
grep -q "port '99999'" "$work/bad2.log" || fail "no port error: $(cat "$work/bad2.log")"
echo "ok: --join refuses non-loopback hosts and bad ports"

port=$(python3 -c "import socket; s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(('127.0.0.1', 0)); print(s.getsockname()[1])")
env -u DISPLAY timeout 300 "$demo" --headless --no-panel --scene "$here/e2e.cfg" --autopilot 14 --deterministic \
    --host "$port" --host-wait 3 --width 480 --height 270 >"$work/host.log" 2>&1 &
host_pid=$!
listening() { grep -q "^host: listening" "$work/host.log"; }
for _ in $(seq 1 600); do
    listening && break
    kill -0 "$host_pid" 2>/dev/null || { cat "$work/host.log"; fail "the host exited early"; }
    sleep 0.1
done
listening || fail "the host did not listen within 60 s"
timeout 300 "$demo" --join "127.0.0.1:$port" --scene "$here/e2e.cfg" --width 480 --height 270 --out "$work/join" \
    --screenshot-every 2 >"$work/log" 2>&1 &
demo_pid=$!
wait "$host_pid"
host_rc=$?
wait "$demo_pid"
join_rc=$?
demo_pid=""
[ "$host_rc" = 0 ] || { cat "$work/host.log"; fail "the host exited with $host_rc"; }
[ "$join_rc" = 0 ] || fail "the --join window exited with $join_rc"

python3 - "$work/host.log" "$work/log" "$work/join" "$here/png_stats.py" <<'PY' || fail "the client did not follow the host"
import glob, re, subprocess, sys
host, join = open(sys.argv[1]).read(), open(sys.argv[2]).read()
h = re.search(r"host: (\d+) clients joined, (\d+) syncs sent, (\d+) acknowledged, (\d+) mismatched hashes, "
              r"geometry hash ([0-9a-f]+)", host)
j = re.search(r"join: (.*); joined yes \(([\d.]+) ms\), (\d+) events, (\d+) syncs checked, (\d+) mismatched hashes, "
              r"(\d+) placements, (\d+) frames drawn, \d+ shots asked, geometry hash ([0-9a-f]+)", join)
assert h and j, (host[-500:], join[-500:])
assert "host closed the connection" in j.group(1), j.group(0)
assert int(h.group(1)) == 1 and int(h.group(4)) == 0, h.group(0)
assert int(h.group(3)) == int(h.group(2)), ("not every sync acknowledged", h.group(0))
events, syncs, mismatched, placements, frames = (int(j.group(k)) for k in (3, 4, 5, 6, 7))
assert mismatched == 0 and syncs > 100 and events > 0 and placements > 0, j.group(0)
assert frames > 30, ("the client drew %d frames" % frames)
assert syncs < 14 * 60, ("the client should have joined late (snapshot + journal tail)", syncs)
assert j.group(8) == h.group(5), ("final geometry hashes differ", h.group(5), j.group(8))
shots = sorted(glob.glob(sys.argv[3] + "/join_*.png"))
assert shots, "no screenshot of the --join window"
out = subprocess.run([sys.executable, sys.argv[4], shots[-1]], capture_output=True, text=True)
var = float(out.stdout.split("var=")[1].split()[0])
assert var > 50, ("blank --join picture", out.stdout)
print("ok: --join followed the host: %d syncs checked, %d events, 0 mismatched hashes, final hash %s equal, "
      "%d frames drawn, late join %s ms" % (syncs, events, j.group(8), frames, j.group(2)))
PY
echo "PASS"
