#!/usr/bin/env bash
# `rubble fracture`: JSON schema, volume conservation, closed and oriented pieces that `rubble check` accepts,
# byte-identical output for the same seed, nothing written on bad input, impact outside, glTF, batch.
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
models="$root/assets/models"
data="$root/tests/data/meshes"
# shellcheck source=tests/support/cli.sh
source "$(dirname "$0")/../support/cli.sh"

# Validates a single-mesh JSON document ($1) against the schema and the invariants; prints the piece count.
check_json() {
    python3 - "$1" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
assert set(d) == {"input", "cut", "dropped_volume", "pieces", "timings_ms"}, d.keys()
assert d["cut"] is True and d["dropped_volume"] >= 0, d
assert set(d["input"]) == {"volume", "triangles", "closed"}, d["input"]
assert isinstance(d["input"]["volume"], float) and isinstance(d["input"]["triangles"], int)
assert d["input"]["closed"] is True
assert set(d["timings_ms"]) == {"cell", "boolean", "islands", "decomposition", "total"}, d["timings_ms"]
assert all(isinstance(v, (int, float)) and v >= 0 for v in d["timings_ms"].values()), d["timings_ms"]
assert len(d["pieces"]) >= 2, "expected at least two pieces"
for p in d["pieces"]:
    assert set(p) == {"volume", "triangles", "closed", "oriented", "center_of_mass", "convex_parts",
                      "concavity"}, p.keys()
    assert 0 <= p["concavity"] < 0.5, p
    assert p["closed"] is True and p["oriented"] is True, p
    assert p["volume"] > 0 and p["triangles"] >= 4 and p["convex_parts"] >= 1, p
    assert len(p["center_of_mass"]) == 3 and all(isinstance(c, float) for c in p["center_of_mass"]), p
total = sum(p["volume"] for p in d["pieces"])
vin = d["input"]["volume"]
assert abs(total + d["dropped_volume"] - vin) <= 1e-6 * vin, (total, vin)
print(len(d["pieces"]))
PY
}

# One cell through a 588-triangle cube, written as OBJ + MTL.
"$RUBBLE" fracture "$models/cube_588.obj" --impact 0.9,0.2,-0.1 --impulse 400 --seed 7 -o "$tmp/a" --json \
    >"$tmp/a.json" || fail "cube_588 should exit 0"
n=$(check_json "$tmp/a.json") || fail "cube_588 JSON: $(cat "$tmp/a.json")"
[ "$(ls "$tmp/a"/piece_*.obj | wc -l)" -eq "$n" ] || fail "expected $n OBJ files in $(ls "$tmp/a")"
grep -q "^newmtl interior" "$tmp/a/piece_000.mtl" || fail "piece_000.mtl has no interior material"
grep -q "^usemtl interior" "$tmp/a/piece_000.obj" || fail "piece_000.obj uses no interior material"
"$RUBBLE" check "$tmp/a"/piece_*.obj >"$tmp/check.txt" || fail "rubble check rejects the pieces: $(cat "$tmp/check.txt")"

# Same seed: byte-identical files (also through an output path with a trailing slash); another seed: different
# pieces.
"$RUBBLE" fracture "$models/cube_588.obj" --impact 0.9,0.2,-0.1 --impulse 400 --seed 7 -o "$tmp/b/" >/dev/null \
    || fail "second run should exit 0"
diff -r "$tmp/a" "$tmp/b" >/dev/null || fail "same seed gave different files"
"$RUBBLE" fracture "$models/cube_588.obj" --impact 0.9,0.2,-0.1 --impulse 400 --seed 8 -o "$tmp/c" >/dev/null \
    || fail "seed 8 should exit 0"
! diff -r "$tmp/a" "$tmp/c" >/dev/null || fail "seeds 7 and 8 gave identical files"

# Shatter pattern with an explicit backend on a scene object; text summary.
"$RUBBLE" fracture "$models/wall.obj" --impact 0,3,0.8 --impulse 900 --cells 5 --backend corefine --seed 3 \
    -o "$tmp/wall" --json >"$tmp/wall.json" || fail "wall shatter should exit 0"
n=$(check_json "$tmp/wall.json") || fail "wall JSON: $(cat "$tmp/wall.json")"
[ "$n" -ge 3 ] || fail "a 5-cell shatter should give at least 3 pieces, got $n"
"$RUBBLE" check "$tmp/wall"/piece_*.obj >/dev/null || fail "rubble check rejects the wall pieces"
"$RUBBLE" fracture "$models/cube_12.obj" --impact 0.99,0,0 --backend nef -o "$tmp/text" >"$tmp/text.txt" \
    || fail "nef backend should exit 0"
grep -q "pieces written to" "$tmp/text.txt" || fail "text summary: $(cat "$tmp/text.txt")"

# Rough cut faces: --material concrete cuts with its preset (more triangles, still closed and accepted by
# `rubble check`, cut faces in "interior"); --roughness 0 is the flat cut, byte for byte; the same seed, the
# same bytes.
"$RUBBLE" fracture "$models/cube_588.obj" --impact 0.9,0.2,-0.1 --impulse 400 --seed 7 --material concrete \
    -o "$tmp/rough" --json >"$tmp/rough.json" || fail "--material concrete should exit 0"
check_json "$tmp/rough.json" >/dev/null || fail "rough JSON: $(cat "$tmp/rough.json")"
"$RUBBLE" check "$tmp/rough"/piece_*.obj >"$tmp/check.txt" || fail "rubble check rejects rough pieces: $(cat "$tmp/check.txt")"
grep -q "^usemtl interior" "$tmp/rough/piece_000.obj" || fail "rough piece_000.obj uses no interior material"
python3 - "$tmp/a.json" "$tmp/rough.json" <<'PY' || fail "rough pieces should have more triangles than flat ones"
import json, sys
flat, rough = (sum(p["triangles"] for p in json.load(open(f))["pieces"]) for f in sys.argv[1:])
assert rough > 1.5 * flat, (flat, rough)
PY
"$RUBBLE" fracture "$models/cube_588.obj" --impact 0.9,0.2,-0.1 --impulse 400 --seed 7 --material concrete \
    -o "$tmp/rough2" >/dev/null || fail "second rough run should exit 0"
diff -r "$tmp/rough" "$tmp/rough2" >/dev/null || fail "same seed gave different rough files"
"$RUBBLE" fracture "$models/cube_588.obj" --impact 0.9,0.2,-0.1 --impulse 400 --seed 7 --material concrete \
    --roughness 0 -o "$tmp/flat0" >/dev/null || fail "--roughness 0 should exit 0"
diff -r "$tmp/a" "$tmp/flat0" >/dev/null || fail "--roughness 0 differs from the flat cut"
"$RUBBLE" fracture "$models/cube_588.obj" --impact 0.9,0.2,-0.1 --impulse 400 --seed 7 --roughness 0.1 \
    --hurst 0.5 --feature-size 0.3 -o "$tmp/hand" >/dev/null || fail "--roughness by hand should exit 0"
! diff -r "$tmp/rough" "$tmp/hand" >/dev/null || fail "--roughness by hand gave the preset's files"

# Bad input: exit 2, the file named, nothing written.
expect_2() { # name, then the command line after `rubble fracture`
    local name="$1"; shift
    set +e
    "$RUBBLE" fracture "$@" >"$tmp/err.txt" 2>&1; code=$?
    set -e
    [ "$code" -eq 2 ] || fail "$name: expected exit 2, got $code: $(cat "$tmp/err.txt")"
}
expect_2 garbage "$data/garbage.obj" --impact 0,0,0 -o "$tmp/bad1"
grep -q "garbage.obj" "$tmp/err.txt" || fail "garbage: message does not name the file: $(cat "$tmp/err.txt")"
[ ! -e "$tmp/bad1" ] || fail "garbage: output folder was created"
expect_2 missing "$tmp/missing.obj" --impact 0,0,0 -o "$tmp/bad2"
grep -q "missing.obj" "$tmp/err.txt" || fail "missing: message does not name the file"
expect_2 open "$data/open_cube.obj" --impact 0.5,0.5,0.5 -o "$tmp/bad3"
grep -q "open_cube.obj" "$tmp/err.txt" || fail "open mesh: message does not name the file"
expect_2 "batch with one bad file" "$models/cube_12.obj" "$data/garbage.obj" --impact 0,0,0 -o "$tmp/bad4"
expect_2 "bad impact" "$models/cube_12.obj" --impact 1,2 -o "$tmp/bad5"
expect_2 "bad backend" "$models/cube_12.obj" --impact 0,0,0 --backend magic -o "$tmp/bad6"
expect_2 "bad hurst" "$models/cube_12.obj" --impact 0.99,0,0 --roughness 0.1 --hurst 2 -o "$tmp/bad7"
grep -q "hurst" "$tmp/err.txt" || fail "bad hurst: message does not name the parameter: $(cat "$tmp/err.txt")"
expect_2 "bad material" "$models/cube_12.obj" --impact 0.99,0,0 --material cheese -o "$tmp/bad8"
grep -q "concrete" "$tmp/err.txt" || fail "bad material: message does not list the materials"
for d in bad1 bad2 bad3 bad4 bad5 bad6 bad7 bad8; do [ ! -e "$tmp/$d" ] || fail "$d: output folder was created"; done
mkdir "$tmp/full" && touch "$tmp/full/keep"
expect_2 "non-empty output folder" "$models/cube_12.obj" --impact 0.99,0,0 -o "$tmp/full"
[ "$(ls "$tmp/full")" = keep ] || fail "non-empty output folder was changed"

mkdir "$tmp/empty"
"$RUBBLE" fracture "$models/cube_12.obj" --impact 0.99,0,0 --backend fast -o "$tmp/empty" >/dev/null \
    || fail "an existing empty output folder should be used"
[ -s "$tmp/empty/piece_000.obj" ] || fail "nothing written into the existing empty folder"

# Impact outside the mesh: exit 3, said plainly, no pieces, nothing written.
set +e
"$RUBBLE" fracture "$models/cube_12.obj" --impact 50,50,50 -o "$tmp/out" --json >"$tmp/out.json" 2>"$tmp/out.txt"
code=$?
set -e
[ "$code" -eq 3 ] || fail "impact outside: expected exit 3, got $code"
grep -q "misses" "$tmp/out.txt" || fail "impact outside: no plain message: $(cat "$tmp/out.txt")"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['pieces']==[], d" "$tmp/out.json" \
    || fail "impact outside: pieces in $(cat "$tmp/out.json")"
[ ! -e "$tmp/out" ] || fail "impact outside: output folder was created"

# glTF: one node per piece at the scene root, each with its convex parts as "-convcolonly" children; the
# source material (with its texture, copied) and the interior; positions + normals + UVs.
"$RUBBLE" fracture "$models/column.obj" --impact 1.0,5,0 --impulse 400 --seed 2 --format gltf -o "$tmp/g" \
    --json >"$tmp/g.json" || fail "glTF run should exit 0"
n=$(check_json "$tmp/g.json") || fail "column JSON: $(cat "$tmp/g.json")"
python3 - "$tmp/g/pieces.gltf" "$n" "$tmp/g.json" <<'PY' || fail "glTF check failed"
import json, sys
d = json.load(open(sys.argv[1]))
n = int(sys.argv[2])
pieces = json.load(open(sys.argv[3]))["pieces"]
assert d["asset"]["version"] == "2.0"
roots = d["scenes"][0]["nodes"]
assert len(roots) == n, (len(roots), n)
names = [m["name"] for m in d["materials"]]
assert names == ["column", "interior"], names
assert d["images"] == [{"uri": "textures/concrete.png"}], d.get("images")
assert d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] == {"index": 0}
for r, piece in zip(roots, pieces):
    node = d["nodes"][r]
    assert len(node["translation"]) == 3
    prims = d["meshes"][node["mesh"]]["primitives"]
    assert {p["material"] for p in prims} <= {0, 1} and len(prims) >= 1
    for p in prims:
        assert {"POSITION", "NORMAL", "TEXCOORD_0"} <= set(p["attributes"]), p
    parts = [d["nodes"][c] for c in node["children"]]
    assert len(parts) == piece["convex_parts"] >= 1, (len(parts), piece)
    assert all(c["name"].startswith(node["name"] + "_hull_") and c["name"].endswith("-convcolonly") for c in parts)
    assert all("material" not in p for c in parts for p in d["meshes"][c["mesh"]]["primitives"])
    extras = node["extras"]["rubble"]
    assert abs(extras["volume"] - piece["volume"]) <= 1e-12 * piece["volume"], (extras, piece)
    assert extras["mass"] == extras["volume"] and len(extras["inertia"]) == 3
    assert all(abs(a - b) <= 1e-12 for a, b in zip(extras["center_of_mass"], node["translation"]))
assert any(p["material"] == 1 for m in d["meshes"] for p in m["primitives"] if "material" in p), "no interior"
assert d["buffers"][0]["uri"].startswith("data:application/octet-stream;base64,")
PY
[ "$(ls "$tmp/g")" = "pieces.gltf
textures" ] || fail "glTF output should be the file and its textures: $(ls "$tmp/g")"
cmp "$tmp/g/textures/concrete.png" "$root/assets/textures/concrete.png" || fail "glTF: texture not copied"

# Batch: three meshes in parallel, one folder each, {"results":[...]} with "file".
"$RUBBLE" fracture "$models/cube_12.obj" "$models/wall.obj" "$models/pyramid.obj" --impact 0,0.5,0 \
    --impulse 100 -o "$tmp/batch" --json >"$tmp/batch.json" 2>"$tmp/batch.err" || fail "batch should exit 0"
for m in cube_12 wall pyramid; do
    [ -s "$tmp/batch/$m/piece_000.obj" ] || fail "batch: no $m/piece_000.obj"
    "$RUBBLE" check "$tmp/batch/$m"/piece_*.obj >/dev/null || fail "batch: $m pieces invalid"
done
[ "$(ls "$tmp/batch" | wc -l)" -eq 3 ] || fail "batch: expected 3 folders, got $(ls "$tmp/batch")"
python3 - "$tmp/batch.json" <<'PY' || fail "batch JSON: $(cat "$tmp/batch.json")"
import json, sys
d = json.load(open(sys.argv[1]))
assert set(d) == {"results"} and len(d["results"]) == 3
assert [r["file"].split("/")[-1] for r in d["results"]] == ["cube_12.obj", "wall.obj", "pyramid.obj"]
for r in d["results"]:
    assert set(r) == {"file", "input", "cut", "dropped_volume", "pieces", "timings_ms"}, r.keys()
    assert len(r["pieces"]) >= 2 and abs(sum(p["volume"] for p in r["pieces"]) - r["input"]["volume"]) <= 1e-6 * r["input"]["volume"]
PY
[ ! -s "$tmp/batch.err" ] || fail "batch: stderr is not a terminal, expected no progress bar: $(cat "$tmp/batch.err")"
exit 0
