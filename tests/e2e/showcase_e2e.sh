#!/usr/bin/env bash
# Headless showcase run of rubble-demo (EGL surfaceless): --demolish keeps blasting demolition_block.cfg and
# the stats lines (the HUD's numbers) carry the live, awake and frozen piece counts; pieces appear and grow,
# and resting ones freeze. report.json ends with the same counts. The run's sound, captured to a WAV file
# without a device, holds impacts, breaks, debris hitting the ground and collapses within the voice limit.
# Usage: showcase_e2e.sh PATH/TO/rubble-demo SCENE
set -uo pipefail
demo=${1:?usage: showcase_e2e.sh PATH/TO/rubble-demo SCENE}
scene=${2:?usage: showcase_e2e.sh PATH/TO/rubble-demo SCENE}
work=$(mktemp -d /tmp/rubble-showcase.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() {
    echo "FAIL: $*"
    tail -n 20 "$work/log" 2>/dev/null
    exit 1
}
env -u DISPLAY timeout 350 "$demo" --headless --scene "$scene" --showcase --demolish 0.5 --autopilot 4 \
    --width 320 --height 180 --stats --stats-every 20 --out "$work/out" --audio-wav "$work/sound.wav" >"$work/log" 2>&1 ||
    fail "rubble-demo exited with $?"
# value FIELD LINE: a field of the LINE-th stats line (1 = first, $ = last)
value() { grep '^stats ' "$work/log" | sed -n "$2p" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
lines=$(grep -c '^stats ' "$work/log")
[ "$lines" -ge 10 ] || fail "expected at least 10 stats lines, got $lines"
for f in pieces awake frozen; do
    [ -n "$(value "$f" '$')" ] || fail "the stats line has no $f= field"
done
first=$(value pieces 1)
last=$(value pieces '$')
[ "$last" -gt "$first" ] && [ "$last" -gt 50 ] || fail "pieces did not grow: $first at first, $last at the end"
frozen=$(grep '^stats ' "$work/log" | tr ' ' '\n' | sed -n 's/^frozen=//p' | sort -n | tail -n 1)
[ "$frozen" -gt 0 ] || fail "no piece was ever frozen"
awake=$(grep '^stats ' "$work/log" | tr ' ' '\n' | sed -n 's/^awake=//p' | sort -n | tail -n 1)
[ "$awake" -gt 0 ] || fail "no piece was ever awake"
python3 - "$work/out/report.json" "$last" "$(value awake '$')" "$(value frozen '$')" "$work/sound.wav" <<'PY' ||
import array, json, sys, wave
r = json.load(open(sys.argv[1]))
live, awake, frozen = map(int, sys.argv[2:5])
a = r["audio"]
assert not a["device"], "a headless run opened an audio device"
assert a["impacts"] > 0 and a["breaks"] > 0 and a["debris"] > 0 and a["collapses"] > 0, a
assert a["events"] == a["impacts"] + a["breaks"] + a["debris"] + a["collapses"], a
assert a["played"] + a["quiet"] + a["refused"] == a["events"], a
assert 0 < a["peak_voices"] <= a["max_voices"], a
with wave.open(sys.argv[5]) as w:
    assert (w.getnchannels(), w.getframerate(), w.getsampwidth()) == (2, 44100, 2)
    assert w.getnframes() == 4 * 44100, w.getnframes()  # the run's 4 s of game time
    pcm = array.array("h", w.readframes(w.getnframes()))
rms = (sum(v * v for v in pcm) / len(pcm)) ** 0.5 / 32767
assert 0.005 < rms and max(map(abs, pcm)) <= 32767, rms
assert r["pieces_live"] == live, (r["pieces_live"], live)
assert r["pieces_awake"] == awake and r["pieces_frozen"] == frozen, (r["pieces_awake"], r["pieces_frozen"])
assert r["latency_ms"]["count"] > 0 and r["latency_ms"]["p99"] >= r["latency_ms"]["p50"] > 0
PY
    fail "report.json or sound.wav disagrees"
echo "ok: --demolish brought pieces from $first to $last (at most $awake awake, $frozen frozen at once)"
