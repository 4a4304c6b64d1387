#!/usr/bin/env bash
# End-to-end test of rubble-demo under Xvfb: real window, real key events (xdotool), assertions on the
# demo's --stats output and on its screenshots.
#   Space fires and impacts follow; P freezes the frame counter and Space resumes it; H shows and hides the
#   key help; N loads the next scene; Esc exits with 0;
#   a screenshot is not blank and differs before and after a hit.
# Usage: demo_e2e.sh PATH/TO/rubble-demo      Exit 77 = skipped (Xvfb or xdotool missing).
set -uo pipefail
demo=${1:?usage: demo_e2e.sh PATH/TO/rubble-demo}
here=$(cd "$(dirname "$0")" && pwd)
for tool in Xvfb xdotool python3; do
    if ! command -v "$tool" >/dev/null; then
        echo "SKIP: $tool is not installed (apt-get install xvfb xdotool python3)"
        exit 77
    fi
done

source "$here/../support/e2e.sh" rubble-e2e 30
start_xvfb 91 140 -screen 0 1280x720x24 -r

"$demo" --scene "$here/e2e.cfg" --stats --stats-every 5 --out "$work/out" --no-panel >"$work/log" 2>&1 &
demo_pid=$!

wait_for 60 have_stats || fail "no stats line within 60 s"

win=$(xdotool search --sync --onlyvisible --name "Rubble" 2>/dev/null | head -n 1)
[ -n "$win" ] || fail "demo window not found"
xdotool windowfocus --sync "$win" 2>/dev/null || xdotool windowfocus "$win"
sleep 0.5
key() { xdotool key --clearmodifiers "$@"; }

# Screenshot before any hit.
shots_taken() { [ "$(ls "$work/out"/shot_*.png 2>/dev/null | wc -l)" -ge "$1" ]; }
key F2
wait_for 20 shots_taken 1 || fail "F2 did not write a screenshot"

# 1-3 pick the weapon (the stats line names it, 1-based).
for k in 3 2 1; do
    picked() { [ "$(field weapon)" = "$k" ]; }
    key "$k"
    wait_for 20 picked || fail "key $k did not pick weapon $k (weapon=$(field weapon))"
done
echo "ok: keys 3, 2, 1 picked the demolition charge, the heavy shell and the cannon"

# Space fires; impacts follow.
s0=$(field shots)
xdotool keydown space
sleep 1.2
xdotool keyup space
fired() { [ "$(field shots)" -gt "$s0" ]; }
wait_for 20 fired || fail "Space did not fire (shots stayed at $s0)"
hit() { [ "$(field impacts)" -gt 0 ]; }
wait_for 30 hit || fail "shots fired ($(field shots)) but no impact followed"
echo "ok: Space fired $(field shots) shots, $(field impacts) impacts"
sleep 0.3
key F2
wait_for 20 shots_taken 2 || fail "second screenshot missing"

# P pauses: the frame counter stops while stats lines keep coming.
key p
is_paused() { [ "$(field paused)" = "1" ]; }
wait_for 20 is_paused || fail "P did not pause"
f1=$(field frame)
sleep 2
f2=$(field frame)
[ "$f1" = "$f2" ] || fail "frame counter moved while paused ($f1 -> $f2)"
[ "$(field paused)" = "1" ] || fail "paused flag dropped"
echo "ok: P froze the frame counter at $f1"

# H shows the key help over the (frozen) picture and hides it again.
key F2
wait_for 20 shots_taken 3 || fail "screenshot 3 missing"
key h
sleep 0.5
key F2
wait_for 20 shots_taken 4 || fail "screenshot 4 missing"
key h
sleep 0.5
key F2
wait_for 20 shots_taken 5 || fail "screenshot 5 missing"
help_on=$(python3 "$here/png_stats.py" "$work/out/shot_0003.png" "$work/out/shot_0004.png" | sed -n 's/.*diff=\([0-9.]*\).*/\1/p')
help_off=$(python3 "$here/png_stats.py" "$work/out/shot_0003.png" "$work/out/shot_0005.png" | sed -n 's/.*diff=\([0-9.]*\).*/\1/p')
python3 -c "import sys; sys.exit(0 if float('$help_on') > 0.5 and float('$help_on') > 5 * float('$help_off') else 1)" ||
    fail "H did not show and hide the help overlay (diff with help $help_on, after closing it $help_off)"
echo "ok: H showed the key help (picture diff $help_on) and hid it ($help_off)"
key space
resumed() { [ "$(field paused)" = "0" ] && [ "$(field frame)" -gt "$f2" ]; }
wait_for 20 resumed || fail "Space did not unpause"
echo "ok: Space resumed (frame $(field frame))"

# Screenshots: not blank, and different before and after the hit.
stats=$(python3 "$here/png_stats.py" "$work/out/shot_0001.png" "$work/out/shot_0002.png") || fail "png_stats failed"
echo "screenshots: $stats"
var=$(echo "$stats" | sed -n 's/.*var=\([0-9.]*\).*/\1/p')
diff=$(echo "$stats" | sed -n 's/.*diff=\([0-9.]*\).*/\1/p')
python3 -c "import sys; sys.exit(0 if float('$var') > 50 else 1)" || fail "screenshot looks blank (variance $var)"
python3 -c "import sys; sys.exit(0 if float('$diff') > 0.05 else 1)" || fail "screenshots before/after the hit are the same (diff $diff)"

# F5 saves a snapshot of the destroyed world, F9 loads it back, and the game plays on.
key F5
saved() { grep -q '^F5: saved ' "$work/log"; }
wait_for 20 saved || fail "F5 did not save: $(grep '^F5' "$work/log")"
[ -s "$work/out/quicksave.rsnap" ] || fail "F5 wrote no quicksave.rsnap"
key F9
loaded() { grep -q '^F9: loaded ' "$work/log"; }
wait_for 20 loaded || fail "F9 did not load: $(grep '^F9' "$work/log")"
f3=$(field frame)
moving() { [ "$(field frame)" -gt "$f3" ]; }
wait_for 20 moving || fail "the game stopped after F9"
echo "ok: $(grep '^F9' "$work/log" | tail -n 1)"

# N loads the next scene (the demolition scene after e2e.cfg) and the game plays on in it.
key n
next_scene() { grep -q '^scene: .*demolition.cfg' "$work/log"; }
wait_for 60 next_scene || fail "N did not load the next scene: $(grep -E '^(scene|error)' "$work/log")"
f4=$(field frame)
moving_on() { [ "$(field frame)" -gt "$f4" ]; }
wait_for 30 moving_on || fail "the game stopped after N"
echo "ok: N loaded $(grep '^scene: ' "$work/log" | tail -n 1 | cut -d' ' -f2-)"

# Esc quits with status 0.
key Escape
for _ in $(seq 1 200); do
    kill -0 "$demo_pid" 2>/dev/null || break
    sleep 0.1
done
if kill -0 "$demo_pid" 2>/dev/null; then fail "Esc did not quit within 20 s"; fi
wait "$demo_pid"
rc=$?
demo_pid=""
[ "$rc" -eq 0 ] || fail "rubble-demo exited with $rc after Esc"
echo "ok: Esc exited with 0"
echo "PASS"
