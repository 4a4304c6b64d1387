#!/usr/bin/env bash
# Engine-ready output of `rubble fracture`: glTF with -convcolonly collision children read back by `rubble
# check` node by node and fractured again (the piece at the impact, the others kept, volume conserved); OBJ
# with UCX_ parts and the source texture kept; --depth node trees with bonds, volume conserved every level.
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
models="$root/assets/models"
# shellcheck source=tests/support/cli.sh
source "$(dirname "$0")/../support/cli.sh"

# glTF with collision, read back: every node valid, each with convex parts inside its hull (rubble check tests
# both), textures copied.
"$RUBBLE" fracture "$models/cube_588.obj" --impact 0.9,0.2,-0.1 --impulse 400 --cells 4 --seed 7 --format gltf \
    -o "$tmp/a" --json >"$tmp/a.json" || fail "first fracture should exit 0"
cmp "$tmp/a/textures/concrete.png" "$root/assets/textures/concrete.png" || fail "texture not copied"
"$RUBBLE" check "$tmp/a/pieces.gltf" --json >"$tmp/check.json" || fail "rubble check rejects pieces.gltf: $(cat "$tmp/check.json")"
python3 - "$tmp/a.json" "$tmp/check.json" <<'PY' || fail "check of pieces.gltf: $(cat "$tmp/check.json")"
import json, sys
run = json.load(open(sys.argv[1]))
check = json.load(open(sys.argv[2]))["meshes"]
pieces = run["pieces"]
assert len(check) == len(pieces) >= 3, (len(check), len(pieces))
for c, p in zip(check, pieces):
    assert c["valid"] and c["closed"] and c["problems"] == [], c
    assert c["collision_parts"] == p["convex_parts"] >= 1, (c, p)
    assert abs(c["volume"] - p["volume"]) <= 1e-5 * p["volume"], (c["volume"], p["volume"])  # float storage
    diag = sum((h - l) ** 2 for l, h in zip(*c["bbox"])) ** 0.5
    assert c["collision_outside_hull"] <= 1e-6 * diag, c
PY

# Fracture the set again: the piece containing the impact is fractured, the others are written unchanged.
target=$(python3 -c 'import json, sys
p = max(json.load(open(sys.argv[1]))["pieces"], key=lambda p: p["volume"])
print(",".join(repr(c) for c in p["center_of_mass"]))' "$tmp/a.json")
"$RUBBLE" fracture "$tmp/a/pieces.gltf" --impact "$target" --impulse 100 --cells 3 --seed 2 --format gltf \
    -o "$tmp/b" --json >"$tmp/b.json" 2>"$tmp/b.err" || fail "second fracture should exit 0: $(cat "$tmp/b.err")"
python3 - "$tmp/a.json" "$tmp/b.json" "$tmp/b/pieces.gltf" <<'PY' || fail "second fracture: $(cat "$tmp/b.json")"
import json, sys
a = json.load(open(sys.argv[1]))
b = json.load(open(sys.argv[2]))
doc = json.load(open(sys.argv[3]))
big = max(range(len(a["pieces"])), key=lambda i: a["pieces"][i]["volume"])
assert b["object"] == "piece_%03d" % big, (b["object"], big)
assert b["kept"] == len(a["pieces"]) - 1, b
assert abs(b["input"]["volume"] - a["pieces"][big]["volume"]) <= 1e-5 * b["input"]["volume"], b["input"]
roots = [doc["nodes"][r] for r in doc["scenes"][0]["nodes"]]
assert len(roots) == b["kept"] + len(b["pieces"]), len(roots)
names = [n["name"] for n in roots]
assert "piece_%03d" % big not in names and all(n.startswith("piece_%03d_" % big) for n in names[b["kept"]:]), names
total = sum(n["extras"]["rubble"]["volume"] for n in roots) + b["dropped_volume"]
vin = a["input"]["volume"] - a["dropped_volume"]
assert abs(total - vin) <= 1e-5 * vin, (total, vin)
assert all(n["name"].endswith("-convcolonly") for r in roots for n in (doc["nodes"][c] for c in r["children"]))
PY
"$RUBBLE" check "$tmp/b/pieces.gltf" >/dev/null || fail "rubble check rejects the refractured set"

# OBJ: UCX_ objects and the texture kept (copied, the map re-pathed).
"$RUBBLE" fracture "$models/column.obj" --impact 1.0,5,0 --impulse 400 --seed 2 -o "$tmp/o" --json \
    >"$tmp/o.json" || fail "OBJ run should exit 0"
grep -q "^map_Kd textures/concrete.png$" "$tmp/o/piece_000.mtl" || fail "map_Kd not re-pathed: $(cat "$tmp/o/piece_000.mtl")"
cmp "$tmp/o/textures/concrete.png" "$root/assets/textures/concrete.png" || fail "OBJ: texture not copied"
grep -q "^o UCX_piece_000_00$" "$tmp/o/piece_000.obj" || fail "no UCX_ object in piece_000.obj"
"$RUBBLE" check "$tmp/o"/piece_*.obj --json >"$tmp/ocheck.json" || fail "rubble check rejects the OBJ pieces"
python3 - "$tmp/o.json" "$tmp/ocheck.json" <<'PY' || fail "OBJ check: $(cat "$tmp/ocheck.json")"
import json, sys
pieces = json.load(open(sys.argv[1]))["pieces"]
check = json.load(open(sys.argv[2]))["meshes"]
assert [c["object"] for c in check] == ["piece_%03d" % i for i in range(len(pieces))], check
for c, p in zip(check, pieces):
    assert c["valid"] and c["collision_parts"] == p["convex_parts"] >= 1, (c, p)
    assert c["volume"] == p["volume"], (c["volume"], p["volume"])  # exact numbers in OBJ
    diag = sum((h - l) ** 2 for l, h in zip(*c["bbox"])) ** 0.5
    assert c["collision_outside_hull"] <= 0.01 * diag, c  # kPartHullTolerance (CollisionTolerance.hpp)
PY

# An interior texture gets its own slot.
"$RUBBLE" fracture "$models/cube_12.obj" --impact 0.99,0,0 --interior-texture "$root/assets/textures/concrete.png" \
    --format gltf -o "$tmp/i" >/dev/null || fail "--interior-texture run should exit 0"
python3 - "$tmp/i/pieces.gltf" <<'PY' || fail "interior texture slot"
import json, sys
d = json.load(open(sys.argv[1]))
m = {m["name"]: m for m in d["materials"]}
assert "baseColorTexture" in m["interior"]["pbrMetallicRoughness"], m
PY

# Hierarchical pre-fracture: a node tree of chunks, each with its collision parts; bonds between siblings in
# extras; volume conserved on every level; --json reports each level.
"$RUBBLE" fracture "$models/cube_588.obj" --impact 0.9,0.2,-0.1 --impulse 400 --cells 4 --depth 3 --seed 7 \
    --format gltf -o "$tmp/d" --json >"$tmp/d.json" || fail "--depth 3 should exit 0"
python3 - "$tmp/d.json" "$tmp/d/pieces.gltf" <<'PY' || fail "--depth 3: $(cat "$tmp/d.json")"
import json, sys
run = json.load(open(sys.argv[1]))
doc = json.load(open(sys.argv[2]))
vin = run["input"]["volume"]
levels = run["levels"]
assert [l["level"] for l in levels] == [1, 2, 3], levels
for l in levels:
    assert set(l) == {"level", "pieces", "volume", "dropped_volume", "bonds", "failed"}, l
    assert abs(l["volume"] + l["dropped_volume"] - vin) <= 1e-9 * vin, l
assert levels[0]["pieces"] == len(run["pieces"]) >= 3 and levels[1]["pieces"] > levels[0]["pieces"], levels
assert levels[2]["pieces"] > levels[1]["pieces"] and all(l["bonds"] >= 1 for l in levels), levels
nodes = doc["nodes"]
chunks = {n["name"]: n for n in nodes if not n["name"].endswith("-convcolonly")}
by_level = {}
for name, n in chunks.items():
    r = n["extras"]["rubble"]
    by_level.setdefault(r["level"], []).append(n)
    hulls = [nodes[c] for c in n.get("children", []) if nodes[c]["name"].endswith("-convcolonly")]
    assert hulls, "chunk %s has no collision parts" % name
    kids = [nodes[c] for c in n.get("children", []) if not nodes[c]["name"].endswith("-convcolonly")]
    for k in kids:
        assert k["extras"]["rubble"]["parent"] == name and k["extras"]["rubble"]["level"] == r["level"] + 1
    if kids:
        assert abs(sum(k["extras"]["rubble"]["volume"] for k in kids) - r["volume"]) <= 1e-9 * r["volume"], name
        kid_names = {k["name"] for k in kids}
        for b in r["bonds"]:
            assert b["a"] in kid_names and b["b"] in kid_names and b["area"] > 0 and len(b["centroid"]) == 3, b
assert [len(by_level[l]) for l in (1, 2, 3)] == [l["pieces"] - l["failed"] * 0 for l in levels], \
    ([len(by_level[l]) for l in (1, 2, 3)], levels)
assert len(doc["scenes"][0]["nodes"]) == levels[0]["pieces"]
roots = {nodes[r]["name"] for r in doc["scenes"][0]["nodes"]}
bonds = doc["scenes"][0]["extras"]["rubble"]["bonds"]
assert len(bonds) == levels[0]["bonds"] and all(b["a"] in roots and b["b"] in roots for b in bonds), bonds
PY
"$RUBBLE" check "$tmp/d/pieces.gltf" >/dev/null || fail "rubble check rejects the node tree"
set +e
"$RUBBLE" fracture "$models/cube_12.obj" --impact 0.99,0,0 --depth 2 -o "$tmp/dobj" >"$tmp/err.txt" 2>&1
code=$?
set -e
[ "$code" -eq 2 ] && grep -q "gltf" "$tmp/err.txt" || fail "--depth 2 with OBJ output: expected exit 2, got $code"

exit 0
