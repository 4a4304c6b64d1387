#!/usr/bin/env bash
# `rubble decompose`: JSON fields, convex input gives one part, --max-parts, -o parts file, exit codes.
set -eu
data="$(cd "$(dirname "$0")/../data/meshes" && pwd)"
# shellcheck source=tests/support/cli.sh
source "$(dirname "$0")/../support/cli.sh"

"$RUBBLE" decompose --json "$data/cube.obj" >"$tmp/cube.json" || fail "cube should exit 0"
python3 - "$tmp/cube.json" <<'PY' || fail "cube JSON: $(cat "$tmp/cube.json")"
import json, sys
d = json.load(open(sys.argv[1]))
assert set(d) == {"parts", "mesh_volume", "hull_volume", "excess", "concavity", "ms"}, d
assert d["parts"] == 1 and abs(d["mesh_volume"] - 1) < 1e-12 and abs(d["excess"]) < 1e-9 and d["ms"] >= 0, d
assert d["concavity"] < 1e-9, d  # a convex mesh and its hull: no surface point inside a part
PY
"$RUBBLE" decompose "$data/cube.obj" | grep -q "1 convex part" || fail "text output"
# A convex box is one part even at concavity 0; the fighter's hull alone covers pockets 5 % of its diagonal deep.
models="$data/../../../assets/models"
"$RUBBLE" decompose "$models/cube_588.obj" --concavity 0 --max-parts 400 --json >"$tmp/box.json" ||
    fail "convex box at concavity 0"
python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); assert d["parts"] == 1, d' "$tmp/box.json" ||
    fail "a convex box at concavity 0 should be one part: $(cat "$tmp/box.json")"
"$RUBBLE" decompose "$models/fighter.obj" --max-parts 1 --json >"$tmp/one.json" || fail "fighter in one part"
"$RUBBLE" decompose "$models/fighter.obj" --json >"$tmp/many.json" || fail "fighter"
python3 - "$tmp/one.json" "$tmp/many.json" <<'PY' || fail "fighter concavity: $(cat "$tmp/one.json" "$tmp/many.json")"
import json, sys
one, many = (json.load(open(f)) for f in sys.argv[1:])
assert one["parts"] == 1 and one["concavity"] > 0.05, one
assert many["parts"] > 1 and 0 < many["concavity"] < 1, many
PY

# A non-convex mesh (two cubes joined in an L) gives several parts, at most --max-parts.
cat >"$tmp/l.obj" <<'OBJ'
v 0 0 0
v 2 0 0
v 2 1 0
v 1 1 0
v 1 2 0
v 0 2 0
v 0 0 1
v 2 0 1
v 2 1 1
v 1 1 1
v 1 2 1
v 0 2 1
f 4 6 5
f 4 1 6
f 4 2 1
f 4 3 2
f 10 11 12
f 10 12 7
f 10 7 8
f 10 8 9
f 1 2 8 7
f 2 3 9 8
f 3 4 10 9
f 4 5 11 10
f 5 6 12 11
f 6 1 7 12
OBJ
"$RUBBLE" decompose --json "$tmp/l.obj" >"$tmp/l.json" || fail "L should exit 0"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['parts']>=2 and d['excess']<1e-6, d" \
    "$tmp/l.json" || fail "L JSON: $(cat "$tmp/l.json")"
"$RUBBLE" decompose --json --max-parts 1 "$tmp/l.obj" | grep -qF '"parts":1' || fail "--max-parts 1"

# -o writes the parts beside the asset (the file a scene loads); an unwritable path exits 1.
"$RUBBLE" decompose --json -o "$tmp/l.parts.json" "$tmp/l.obj" >/dev/null || fail "-o should exit 0"
python3 - "$tmp/l.parts.json" <<'PY' || fail "parts file: $(head -c 300 "$tmp/l.parts.json")"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["format"] == "rubble-decomposition" and d["version"] == 2 and len(d["mesh_hash"]) == 16, d.keys()
assert len(d["parts"]) >= 2 and all(len(p["faces"]) >= 4 for p in d["parts"]), d["parts"]
PY
set +e
"$RUBBLE" decompose -o "$tmp/no/such/dir/x.parts.json" "$tmp/l.obj" >/dev/null 2>"$tmp/err.txt"; code=$?
set -e
[ "$code" -eq 1 ] || fail "unwritable -o should exit 1, got $code"
grep -q "x.parts.json" "$tmp/err.txt" || fail "write error does not name the file: $(cat "$tmp/err.txt")"

# Ctrl-C (SIGINT) during a long decomposition: exit 130, "cancelled" on stderr, no parts file written.
python3 - "$tmp/bumpy.obj" <<'PY'
import math, sys
slices, stacks = 80, 40
r = lambda x, y, z: 1 + 0.1 * math.sin(5 * x + 1) * math.sin(4 * y + 2) * math.sin(6 * z)
pts = [(0, 0, 1)]
for i in range(1, stacks):
    t = math.pi * i / stacks
    for j in range(slices):
        p = 2 * math.pi * j / slices
        u = (math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))
        pts.append(tuple(c * r(*u) for c in u))
pts.append((0, 0, -1))
ring = lambda i, j: 1 + (i - 1) * slices + j % slices
tris = [(0, ring(1, j), ring(1, j + 1)) for j in range(slices)]
for i in range(1, stacks - 1):
    for j in range(slices):
        tris += [(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)), (ring(i, j), ring(i + 1, j + 1), ring(i, j + 1))]
tris += [(len(pts) - 1, ring(stacks - 1, j + 1), ring(stacks - 1, j)) for j in range(slices)]
with open(sys.argv[1], "w") as f:
    f.writelines("v %.9f %.9f %.9f\n" % p for p in pts)
    f.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in tris)
PY
set +e
timeout --preserve-status -s INT 1 "$RUBBLE" decompose --threads 1 --max-parts 1024 --concavity 0 -o "$tmp/bumpy.parts.json" \
    "$tmp/bumpy.obj" >/dev/null 2>"$tmp/err.txt"
code=$?
set -e
[ "$code" -eq 130 ] || fail "SIGINT should exit 130, got $code: $(cat "$tmp/err.txt")"
grep -q "cancelled" "$tmp/err.txt" || fail "SIGINT should say cancelled: $(cat "$tmp/err.txt")"
[ ! -e "$tmp/bumpy.parts.json" ] || fail "a cancelled decomposition wrote its parts file"

# Unreadable input: exit 2 with the file named.
set +e
"$RUBBLE" decompose "$tmp/missing.obj" >"$tmp/err.txt" 2>&1; code=$?
set -e
[ "$code" -eq 2 ] || fail "missing file should exit 2, got $code"
grep -q "missing.obj" "$tmp/err.txt" || fail "error does not name the file: $(cat "$tmp/err.txt")"
set +e
"$RUBBLE" decompose "$data/garbage.obj" >/dev/null 2>&1; code=$?
"$RUBBLE" decompose --max-parts 0 "$data/cube.obj" >/dev/null 2>&1; code2=$?
set -e
[ "$code" -eq 2 ] || fail "garbage should exit 2, got $code"
[ "$code2" -eq 2 ] || fail "--max-parts 0 should exit 2, got $code2"
exit 0
