#!/usr/bin/env bash
# rubble-bench render's contract: one JSON row per piece count with the named fields; distant small pieces
# are chips and the meshes drawn stay within the software budget, draw calls do not follow the pieces (and with
# RUBBLE_DEMO_SKIP=lod there are no chips); a bad count is refused with a message naming it.
# Usage: render_contract.sh PATH/TO/rubble-bench PATH/TO/rubble-demo
set -uo pipefail
bench=${1:?usage: render_contract.sh RUBBLE_BENCH RUBBLE_DEMO}
demo=${2:?usage: render_contract.sh RUBBLE_BENCH RUBBLE_DEMO}
work=$(mktemp -d /tmp/rubble-render-contract.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() {
    echo "FAIL: $*"
    cat "$work"/*.err 2>/dev/null | tail -n 20
    exit 1
}
args=(render --pieces 100,2000 --frames 2 --width 320 --height 180 --json --demo "$demo")
env -u DISPLAY "$bench" "${args[@]}" >"$work/on.json" 2>"$work/on.err" || fail "rubble-bench render failed"
env -u DISPLAY RUBBLE_DEMO_SKIP=lod "$bench" "${args[@]}" >"$work/off.json" 2>"$work/off.err" ||
    fail "rubble-bench render with RUBBLE_DEMO_SKIP=lod failed"
python3 - "$work/on.json" "$work/off.json" <<'PY' || fail "rows break the contract"
import json, sys
on, off = (json.load(open(p)) for p in sys.argv[1:3])
assert [r["pieces"] for r in on] == [100, 2000], on
for r in on + off:
    for k in ("pieces", "cpu_ms_per_frame", "draw_calls", "mesh_pieces", "chip_pieces", "other_cpu_cores"):
        assert k in r, (k, r)
    assert r["cpu_ms_per_frame"] > 0
big = on[1]
assert big["chip_pieces"] > 0, big
assert big["mesh_pieces"] <= 600 or big["quality"] != "software", big
assert big["draw_calls"] <= on[0]["draw_calls"] + 1 <= 10, (on[0], big)
assert all(r["chip_pieces"] == 0 for r in off), off
assert off[1]["mesh_pieces"] > big["mesh_pieces"], (off[1], big)
PY
if env -u DISPLAY "$bench" render --pieces 100,5x --demo "$demo" >"$work/bad.out" 2>"$work/bad.err"; then
    fail "--pieces 100,5x was accepted"
fi
grep -q "5x" "$work/bad.err" || fail "the error does not name the bad count: $(cat "$work/bad.err")"
echo "ok: rubble-bench render rows, chips within the budget, LOD off has none, bad counts refused"
