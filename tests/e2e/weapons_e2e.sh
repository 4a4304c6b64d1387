#!/usr/bin/env bash
# Headless end-to-end run of the weapons (EGL, no X server): the autopilot cycles cannon, heavy shell and
# demolition charge (two shots each) on the demolition scene, and every weapon must fracture something; the
# report credits each fracture to the weapon whose impact caused it, and the building comes down. Also a --record/--replay round trip of
# the adaptive pattern (chips and shatters decided per impact) with all three weapons.
# Usage: weapons_e2e.sh PATH/TO/rubble-demo
set -uo pipefail
demo=${1:?usage: weapons_e2e.sh PATH/TO/rubble-demo}
here=$(cd "$(dirname "$0")" && pwd)
source "$here/../support/e2e.sh" rubble-weapons 20
scene="$here/../../assets/scenes/demolition.cfg"
[ -f "$scene" ] || fail "missing $scene"

env -u DISPLAY timeout 600 "$demo" --headless --no-panel --scene "$scene" --pattern adaptive --autopilot 30 --width 320 --height 180 \
    --record "$work/w.rjournal" --out "$work/w" >"$work/log" 2>&1 || fail "rubble-demo exited with $?"
python3 - "$work/w/report.json" <<'PY' || fail "weapons: $(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['weapons'])" "$work/w/report.json")"
import json, sys
r = json.load(open(sys.argv[1]))
w = r["weapons"]
assert set(w) == {"cannon", "heavy shell", "demolition charge"}, w
for name, v in w.items():
    assert v["shots"] >= 1, (name, "never fired", v)
    assert v["fractures"] >= 1, (name, "fractured nothing", v)
assert sum(v["fractures"] for v in w.values()) <= r["fractures"], (w, r["fractures"])
assert sum(v["shots"] for v in w.values()) == r["shots"], (w, r["shots"])
print("ok: every weapon fractured something: " + ", ".join(f"{n} {v['shots']} shots {v['fractures']} fractures" for n, v in w.items()))
# The stress solver is on by default: the charge's blast on the ground floor brings the building down.
assert r["bodies_collapsed"] >= 100, ("the building did not come down", r["bodies_collapsed"])
print(f"ok: the building came down ({r['bodies_collapsed']} bodies collapsed, {r['bonds_broken']} bonds broken)")
PY

# --hit, --camera and --hold-fire: the fracture-pattern picture of docs/structure.md (one hit on each pane).
env -u DISPLAY timeout 300 "$demo" --headless --no-panel --no-structure --scene "$here/../../assets/scenes/patterns.cfg" \
    --autopilot 0.3 --camera 0,-3,30,0,-7.5,0 --hold-fire --pattern shatter --cells 32 --width 320 --height 180 \
    --hit=-15,-7,0.05,400 --hit=-5,-8,0.2,60 --hit=5,-7,0.2,60 --hit=15,-7,0.05,60 --out "$work/p" >"$work/p.log" 2>&1 ||
    fail "patterns: rubble-demo exited with $?"
python3 - "$work/p/report.json" <<'PY' || fail "patterns: $(cat "$work/p/report.json")"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["shots"] == 0, ("--hold-fire fired", r["shots"])
assert r["fractures"] == 4, ("one fracture per pane", r["fractures"])
PY
env -u DISPLAY timeout 60 "$demo" --headless --scene "$here/../../assets/scenes/patterns.cfg" --autopilot 0.1 \
    --hit=1,2,x --out "$work/bad" >"$work/bad.log" 2>&1 && fail "a malformed --hit was accepted"
grep -q "expected X,Y,Z,IMPULSE" "$work/bad.log" || fail "no message for a malformed --hit: $(cat "$work/bad.log")"
echo "ok: --hit breaks each pane once, --hold-fire fires nothing, a malformed --hit is refused"

# --charge: one charge under tower.cfg's ground floor; the storeys above break as they land (docs/structure.md).
env -u DISPLAY timeout 300 "$demo" --headless --no-panel --mute --scene "$here/../../assets/scenes/tower.cfg" \
    --autopilot 4 --hold-fire --deterministic --camera 16,-2,20,0,0,0 --charge 0,-12,0,4,20000,1 --width 320 \
    --height 180 --out "$work/t" >"$work/t.log" 2>&1 || fail "tower: rubble-demo exited with $?"
python3 - "$work/t/report.json" <<'PY' || fail "tower: $(cat "$work/t/report.json")"
import json, sys
r = json.load(open(sys.argv[1]))
charge = r["weapons"]["demolition charge"]["fractures"]
assert 1 <= charge <= 5, ("the charge breaks the ground floor only", charge)
assert r["fractures"] >= charge + 10, ("the storeys above break as they land", r["fractures"], charge)
assert r["bodies_collapsed"] >= 20, ("the tower did not come down", r["bodies_collapsed"])
PY
env -u DISPLAY timeout 60 "$demo" --headless --scene "$here/../../assets/scenes/tower.cfg" --autopilot 0.1 \
    --charge=0,0,0,4 --out "$work/badcharge" >"$work/badcharge.log" 2>&1 && fail "a malformed --charge was accepted"
grep -q "expected X,Y,Z,RADIUS,IMPULSE,SECONDS" "$work/badcharge.log" ||
    fail "no message for a malformed --charge: $(cat "$work/badcharge.log")"
echo "ok: one --charge under tower.cfg brings it down, the landings breaking more than the charge; a malformed --charge is refused"

# The autopilot adopts deterministically: its journal replays to the geometry it ended with.
env -u DISPLAY timeout 600 "$demo" --headless --no-panel --scene "$scene" --deterministic --replay "$work/w.rjournal" \
    >"$work/replay.log" 2>&1 || fail "replay exited with $?: $(tail -3 "$work/replay.log")"
recorded=$(sed -n 's/^journal: .*geometry hash \([0-9a-f]*\)$/\1/p' "$work/log")
replayed=$(sed -n 's/^replay: .*geometry hash \([0-9a-f]*\)$/\1/p' "$work/replay.log")
[ -n "$recorded" ] && [ "$recorded" = "$replayed" ] || fail "replayed geometry $replayed differs from recorded $recorded"
echo "ok: the weapons' journal replays to geometry hash $recorded"
echo "PASS"
