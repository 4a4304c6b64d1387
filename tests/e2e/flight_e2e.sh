#!/usr/bin/env bash
# End-to-end flight test of rubble-demo under Xvfb with real key events (xdotool), on a 400 x 400 m ground:
#   flying straight, the world bounds turn the jet back (it stays near the ground it flew 450 m over);
#   diving (W) crashes it into the ground and it respawns 2 s later near its start; R respawns it too;
#   flying into a cube crashes the jet and the blast fractures the cube.
# Usage: flight_e2e.sh PATH/TO/rubble-demo      Exit 77 = skipped (Xvfb or xdotool missing).
set -uo pipefail
demo=${1:?usage: flight_e2e.sh PATH/TO/rubble-demo}
here=$(cd "$(dirname "$0")" && pwd)
for tool in Xvfb xdotool; do
    if ! command -v "$tool" >/dev/null; then
        echo "SKIP: $tool is not installed (apt-get install xvfb xdotool)"
        exit 77
    fi
done
source "$here/../support/e2e.sh" rubble-flight 20
start_xvfb 141 190 -screen 0 640x360x24
"$demo" --scene "$here/bounds.cfg" --stats --stats-every 5 --no-panel --width 640 --height 360 >"$work/log" 2>&1 &
demo_pid=$!

wait_for 60 have_stats || fail "no stats line within 60 s"
win=$(xdotool search --sync --onlyvisible --name "Rubble" 2>/dev/null | head -n 1)
[ -n "$win" ] || fail "demo window not found"
xdotool windowfocus --sync "$win" 2>/dev/null || xdotool windowfocus "$win"

# Bounds: straight ahead the ground ends 200 m away; 15 simulated seconds (450 m) later the jet is still over
# it, having turned back.
turned() { [ "$(field turnbacks)" -gt 0 ]; }
wait_for 60 turned || fail "the bounds never turned the jet back (x=$(field x) z=$(field z))"
f0=$(field frame)
far=0
flown() { [ "$(field frame)" -gt $((f0 + 900)) ]; }
while ! flown; do
    kill -0 "$demo_pid" 2>/dev/null || fail "rubble-demo exited early"
    r=$(python3 -c "print(int(max(abs(float('$(field x)')), abs(float('$(field z)')))))")
    [ "$r" -gt "$far" ] && far=$r
    sleep 0.2
done
[ "$far" -lt 240 ] || fail "the jet left the 400 m ground: $far m from its middle"
[ "$(field crashes)" = 0 ] || fail "the jet crashed while flying level"
echo "ok: the bounds turned the jet back $(field turnbacks) times; it stayed within $far m of the middle"

# Crash: nose down into the ground; the wreck respawns 2 s later near the start.
xdotool keydown w
crashed() { [ "$(field crashes)" -gt 0 ]; }
wait_for 60 crashed || { xdotool keyup w; fail "diving did not crash (x=$(field x) z=$(field z))"; }
xdotool keyup w
fc=$(field frame)
back() { [ "$(field respawns)" -gt 0 ]; }
wait_for 60 back || fail "no respawn after the crash"
fr=$(field frame)
[ $((fr - fc)) -ge 100 ] || fail "respawned after $((fr - fc)) frames, before 2 s"
r=$(python3 -c "print(int(max(abs(float('$(field x)')), abs(float('$(field z)')))))")
[ "$r" -lt 80 ] || fail "respawned $r m from the start"
echo "ok: crash at frame $fc, respawn about $((fr - fc)) frames later, $r m from the start"

# R respawns at once.
r0=$(field respawns)
xdotool key --clearmodifiers r
again() { [ "$(field respawns)" -gt "$r0" ]; }
wait_for 20 again || fail "R did not respawn"
echo "ok: R respawned the jet"
xdotool key --clearmodifiers Escape
wait_exit 20 || fail "Escape did not quit the demo"

# Crash into an object: the jet flies into a cube 70 m ahead; the crash's blast fractures it.
"$demo" --scene "$here/crash.cfg" --stats --stats-every 5 --no-panel --width 640 --height 360 >"$work/log" 2>&1 &
demo_pid=$!
wait_for 60 have_stats || fail "no stats line within 60 s (crash scene)"
wait_for 60 crashed || fail "flying into the cube did not crash"
broke() { [ "$(field fractures)" -gt 0 ]; }
wait_for 30 broke || fail "the crash's blast did not fracture the cube it hit"
wait_for 30 back || fail "no respawn after crashing into the cube"
echo "ok: crashing into the cube broke it ($(field fractures) fractures) and the jet respawned"
echo "PASS"
