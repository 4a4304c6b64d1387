#!/usr/bin/env bash
# `rubble-bench scene` (issue #5): the JSON report's keys and their sense, determinism across worker counts
# in --deterministic mode, a different seed giving a different world, and a clear error for a bad scene file.
# With STRUCTURE.cfg, also the stress solver under fire on that scene: the same world on 1 and 2 workers.
# Usage: scene_contract.sh RUBBLE_BENCH SCENE.cfg [STRUCTURE.cfg]
set -eu
bench="$1"
scene="$2"
structure_scene="${3:-}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "scene_contract.sh: $*"; exit 1; }

run() { # name, then extra arguments
    local name="$1"
    shift
    "$bench" scene "$scene" --seconds 3 --unpaced --deterministic --json "$@" >"$tmp/$name.json" ||
        fail "$name: exit $?"
}
run w1 --workers 1
run w2 --workers 2
run seed2 --workers 1 --seed 2

python3 - "$tmp" <<'PY' || fail "report: $(cat "$tmp/w1.json")"
import json, re, sys, os
d = {n: json.load(open(os.path.join(sys.argv[1], n + ".json"))) for n in ("w1", "w2", "seed2")}
r = d["w1"]
for key in ("frames", "frame_ms", "impacts", "fractures", "latency_ms", "pieces_alive", "volume_error",
            "state_hash", "peak_rss_mb"):
    assert key in r, "missing key " + key
assert r["frames"] == 180, r["frames"]  # 3 s at 1/60 s
for key in ("frame_ms", "latency_ms"):
    s = r[key]
    assert set(s) >= {"p50", "p99", "max"}, s
    assert 0 <= s["p50"] <= s["p99"] <= s["max"], (key, s)
assert r["impacts"] >= 1 and 1 <= r["fractures"] <= r["impacts"], (r["impacts"], r["fractures"])
assert r["latency_ms"]["p50"] > 0, r["latency_ms"]
assert isinstance(r["pieces_alive"], int) and r["pieces_alive"] >= 1, r["pieces_alive"]
assert 0 <= r["volume_error"] < 1e-6, r["volume_error"]
assert re.fullmatch(r"[0-9a-f]{16}", r["state_hash"]), r["state_hash"]
assert 0 < r["peak_rss_mb"] < 256, r["peak_rss_mb"]
assert d["w2"]["state_hash"] == r["state_hash"], ("1 vs 2 workers", r["state_hash"], d["w2"]["state_hash"])
assert d["w2"]["fractures"] == r["fractures"]
assert d["seed2"]["state_hash"] != r["state_hash"], "another seed, another world"
PY

# --rough: the scene flat then rough by material in one process; the rough world holds more triangles.
"$bench" scene "$scene" --seconds 2 --unpaced --deterministic --workers 1 --rough --out "$tmp/rough" \
    >"$tmp/rough.log" || fail "--rough: exit $?"
python3 - "$tmp/rough/$(basename "$scene" .cfg)_rough.csv" <<'PY' || fail "--rough: $(cat "$tmp/rough.log")"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert [r["cuts"] for r in rows] == ["flat", "rough"], rows
flat, rough = rows
assert int(flat["fractures"]) >= 1 and int(rough["fractures"]) >= 1, rows
assert int(rough["world_triangles"]) > int(flat["world_triangles"]), rows
PY

# A scene file that does not exist: exit 2, and the message names it.
if "$bench" scene "$tmp/missing.cfg" --seconds 1 --json >"$tmp/out" 2>"$tmp/err"; then
    fail "a missing scene file must fail"
else
    code=$?
fi
[ "$code" -eq 2 ] || fail "missing scene: exit $code, expected 2"
grep -q "missing.cfg" "$tmp/err" || fail "the error does not name the file: $(cat "$tmp/err")"
if [ -n "$structure_scene" ]; then
    for w in 1 2; do
        "$bench" scene "$structure_scene" --seconds 3 --unpaced --deterministic --json --structure \
            --shots-per-second 10 --pattern shatter --workers "$w" >"$tmp/s$w.json" || fail "structure w$w: exit $?"
    done
    python3 - "$tmp" <<'PY' || fail "structure: $(cat "$tmp/s1.json")"
import json, sys, os
d = {n: json.load(open(os.path.join(sys.argv[1], n + ".json"))) for n in ("s1", "s2")}
a, b = d["s1"], d["s2"]
assert a["fractures"] >= 5, a["fractures"]
assert a["structure"]["bonds_at_start"] > 100, a["structure"]
assert a["state_hash"] == b["state_hash"], ("structure, 1 vs 2 workers", a["state_hash"], b["state_hash"])
assert a["structure"]["bonds_at_end"] == b["structure"]["bonds_at_end"], (a["structure"], b["structure"])
PY
fi
echo "scene_contract.sh: ok"
