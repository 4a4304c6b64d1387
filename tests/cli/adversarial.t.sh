#!/usr/bin/env bash
# The defects of the adversarial pass of issue #35 (round 3), replayed against `rubble`: duplicate object names,
# nested and overlapping shells, decompose of convex, open and huge meshes, huge coordinates, absolute texture
# paths, malformed MTL files.
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
data="$root/tests/data/meshes"
# shellcheck source=tests/support/cli.sh
source "$(dirname "$0")/../support/cli.sh"
# cubes FILE [NAME:CX:HALF[:in]]...: one OBJ object per cube centred at (CX,0,0) with half-size HALF, faces
# outward (inward with ":in"); NAME "-" writes no `o` statement.
cubes() {
    python3 - "$@" <<'PY'
import sys
out = open(sys.argv[1], "w")
base = 0
for spec in sys.argv[2:]:
    name, cx, h, *flag = spec.split(":")
    cx, h = float(cx), float(h)
    if name != "-":
        out.write("o %s\n" % name)
    for z in (-1, 1):
        for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            out.write("v %r %r %r\n" % (cx + x * h, y * h, z * h))
    for f in ((1, 4, 3, 2), (5, 6, 7, 8), (1, 2, 6, 5), (4, 8, 7, 3), (1, 5, 8, 4), (2, 3, 7, 6)):
        f = f[::-1] if flag == ["in"] else f
        out.write("f " + " ".join(str(base + i) for i in f) + "\n")
    base += 8
PY
}
# volume_of DIR: total volume of the objects of every OBJ file in DIR (rubble check --json).
volume_of() {
    "$RUBBLE" check --no-self-intersections --json "$1"/*.obj >"$tmp/vol.json" || true
    python3 -c "import json,sys; print(sum(m['volume'] for m in json.load(open(sys.argv[1]))['meshes']))" \
        "$tmp/vol.json"
}
near() { python3 -c "import sys; a,b=float(sys.argv[1]),float(sys.argv[2]); sys.exit(abs(a-b) > 1e-6*abs(b))" "$1" "$2"; }

# --- 1: objects sharing a name are written under unique names; nothing is overwritten ---------------------------
cubes "$tmp/walls.obj" wall:0:1 wall:5:1 wall:10:1
run "$tmp/w.json" "$RUBBLE" fracture "$tmp/walls.obj" --impact 0,0,1 --cells 4 --impulse 200 -o "$tmp/w" --json
[ "$c" -eq 0 ] || fail "three walls: exit $c: $(cat "$tmp/w.json.err")"
json_ok "$tmp/w.json" "d['kept'] == 2" || fail "three walls JSON: $(cat "$tmp/w.json")"
[ -f "$tmp/w/wall.obj" ] && [ -f "$tmp/w/wall_2.obj" ] || fail "kept walls: $(ls "$tmp/w")"
dropped=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['dropped_volume'])" "$tmp/w.json")
total=$(volume_of "$tmp/w")
near "$(python3 -c "print($total + $dropped)")" 24 || fail "three walls: output volume $total + $dropped, not 24"
cubes "$tmp/named.obj" wall:0:1 wall_000:5:1 wall_001:10:1
run "$tmp/n.json" "$RUBBLE" fracture "$tmp/named.obj" --impact 0,0,1 --cells 4 --impulse 200 -o "$tmp/n" --json
[ "$c" -eq 0 ] || fail "wall, wall_000, wall_001: exit $c: $(cat "$tmp/n.json.err")"
dropped=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['dropped_volume'])" "$tmp/n.json")
total=$(volume_of "$tmp/n")
near "$(python3 -c "print($total + $dropped)")" 24 || fail "wall_000 overwritten: volume $total + $dropped of 24"
grep -q "^o wall_000$" "$tmp/n/wall_000.obj" || fail "the kept object wall_000 was replaced"
run "$tmp/g.json" "$RUBBLE" fracture "$tmp/walls.obj" --impact 0,0,1 --cells 4 --impulse 200 -o "$tmp/g" \
    --format gltf --json
[ "$c" -eq 0 ] || fail "three walls glTF: exit $c"
python3 - "$tmp/g/pieces.gltf" <<'PY' || fail "glTF node names are not unique"
import json, sys
nodes = json.load(open(sys.argv[1]))["nodes"]
names = [n["name"] for n in nodes if not n["name"].endswith("colonly")]
assert len(names) == len(set(names)) and "wall_2" in names, names
PY

# --- 6: nested shells both facing outward are invalid; fracture refuses them ------------------------------------
cubes "$tmp/nested.obj" -:0:1 -:0:0.5
run "$tmp/ne.json" "$RUBBLE" check --json "$tmp/nested.obj"
[ "$c" -eq 1 ] || fail "nested cubes: check exit $c, expected 1"
json_ok "$tmp/ne.json" "'1 shell faces the wrong way for its nesting' in d['meshes'][0]['problems'][0]" \
    || fail "nested cubes: $(cat "$tmp/ne.json")"
run "$tmp/nf.txt" "$RUBBLE" fracture "$tmp/nested.obj" --impact 0.9,0.9,1 --cells 8 -o "$tmp/nf"
[ "$c" -eq 2 ] && grep -q "not a valid solid" "$tmp/nf.txt.err" || fail "nested cubes: fracture exit $c"
[ ! -e "$tmp/nf" ] || fail "nested cubes: something was written"
cubes "$tmp/hollow.obj" -:0:1 -:0:0.5:in
"$RUBBLE" check "$tmp/hollow.obj" >/dev/null || fail "a cube with a cavity (inner shell inward) is valid"

# --- 7: fracture applies the checks of check: overlapping cubes are not a valid solid, nothing is written --------
cubes "$tmp/overlap.obj" -:0:1 -:0.5:1
python3 - "$tmp/overlap.obj" <<'PY'
import sys
lines = open(sys.argv[1]).read().split("\n")
out = []
seen = 0
for l in lines:  # lift the second cube by (0, 0.5, 0.5) so that the two overlap in a corner
    if l.startswith("v "):
        seen += 1
        if seen > 8:
            x, y, z = map(float, l.split()[1:])
            l = "v %r %r %r" % (x, y + 0.5, z + 0.5)
    out.append(l)
open(sys.argv[1], "w").write("\n".join(out))
PY
run "$tmp/oc.txt" "$RUBBLE" check "$tmp/overlap.obj"
[ "$c" -eq 1 ] || fail "overlapping cubes: check exit $c, expected 1"
for impact in 0,0,1 0.5,0.5,1.5 0.2,0.2,0.2; do
    run "$tmp/of.txt" "$RUBBLE" fracture "$tmp/overlap.obj" --impact "$impact" --cells 8 -o "$tmp/of"
    [ "$c" -eq 2 ] || fail "overlapping cubes at $impact: fracture exit $c, expected 2: $(cat "$tmp/of.txt.err")"
    grep -q "not a valid solid.*pairs of triangles intersect" "$tmp/of.txt.err" || fail "$(cat "$tmp/of.txt.err")"
    [ ! -e "$tmp/of" ] || fail "overlapping cubes: something was written"
done

# --- 8: a convex box is one part at concavity 0; --max-parts is bounded -------------------------------------------
run "$tmp/d8.json" timeout 120 "$RUBBLE" decompose "$root/assets/models/cube_10092.obj" --concavity 0 \
    --max-parts 1024 --json
[ "$c" -eq 0 ] && json_ok "$tmp/d8.json" "d['parts'] == 1" || fail "convex box at concavity 0: exit $c, $(cat "$tmp/d8.json")"
run "$tmp/d8b.txt" "$RUBBLE" decompose "$root/assets/models/cube_10092.obj" --concavity 0 --max-parts 100000
[ "$c" -eq 2 ] && grep -q "1024" "$tmp/d8b.txt.err" || fail "--max-parts 100000: exit $c, $(cat "$tmp/d8b.txt.err")"

# --- 9: decompose of an open mesh exits 1, as its --help says ---------------------------------------------------
run "$tmp/d9.json" "$RUBBLE" decompose --json "$data/open_cube.obj"
[ "$c" -eq 1 ] && grep -q "not closed" "$tmp/d9.json.err" || fail "open cube: decompose exit $c: $(cat "$tmp/d9.json.err")"

# --- 10: coordinates beyond 1e50 are invalid input; decompose of a 1e100 cube prints no Qhull diagnostics ------
cubes "$tmp/huge.obj" -:0:1e150
run "$tmp/h.json" "$RUBBLE" check --json "$tmp/huge.obj"
[ "$c" -eq 1 ] && json_ok "$tmp/h.json" "'beyond ±1e+50' in d['meshes'][0]['problems'][0]" \
    || fail "1e150 cube: check exit $c: $(cat "$tmp/h.json")"
run "$tmp/hf.txt" "$RUBBLE" fracture "$tmp/huge.obj" --impact 0,0,1e150 -o "$tmp/hf"
[ "$c" -eq 2 ] && grep -q "not a valid solid" "$tmp/hf.txt.err" || fail "1e150 cube: fracture exit $c"
cubes "$tmp/huge100.obj" -:0:1e100
run "$tmp/hd.txt" "$RUBBLE" decompose "$tmp/huge100.obj"
[ "$c" -eq 1 ] || fail "1e100 cube: decompose exit $c"
grep -q "beyond ±1e+50" "$tmp/hd.txt.err" || fail "1e100 cube: $(cat "$tmp/hd.txt.err")"
! grep -qi "qhull\|QH[0-9]" "$tmp/hd.txt" "$tmp/hd.txt.err" || fail "1e100 cube: Qhull diagnostics printed"

# --- a texture named by an absolute path is not copied -------------------------------------------------------------
mkdir -p "$tmp/model" "$tmp/secret"
echo "secret" >"$tmp/secret/passwd.png"
cubes "$tmp/model/m.obj" -:0:1
printf 'mtllib m.mtl\nusemtl stone\n%s\n' "$(cat "$tmp/model/m.obj")" >"$tmp/model/m.obj"
printf 'newmtl stone\nKd 0.5 0.5 0.5\nmap_Kd %s\n' "$tmp/secret/passwd.png" >"$tmp/model/m.mtl"
run "$tmp/t.txt" "$RUBBLE" fracture "$tmp/model/m.obj" --impact 0,0,1 --impulse 200 -o "$tmp/t"
[ "$c" -eq 0 ] || fail "absolute texture: exit $c: $(cat "$tmp/t.txt.err")"
grep -q "is named by an absolute path: not used" "$tmp/t.txt.err" || fail "no warning: $(cat "$tmp/t.txt.err")"
[ ! -e "$tmp/t/textures" ] || fail "absolute texture copied: $(ls "$tmp/t/textures")"
! grep -rq "passwd" "$tmp/t" || fail "absolute texture referenced in the output"

# --- a malformed MTL is a warning for check, fracture and decompose alike -----------------------------------------
mkdir -p "$tmp/mtl"
cubes "$tmp/mtl/m.obj" -:0:1
printf 'mtllib bad.mtl\n%s\n' "$(cat "$tmp/mtl/m.obj")" >"$tmp/mtl/m.obj"
printf 'Kd 1 1 1\n' >"$tmp/mtl/bad.mtl"
run "$tmp/mc.txt" "$RUBBLE" check "$tmp/mtl/m.obj"
[ "$c" -eq 0 ] && grep -q "bad.mtl:1" "$tmp/mc.txt.err" || fail "malformed MTL: check exit $c: $(cat "$tmp/mc.txt.err")"
run "$tmp/mf.txt" "$RUBBLE" fracture "$tmp/mtl/m.obj" --impact 0,0,1 --impulse 200 -o "$tmp/mf"
[ "$c" -eq 0 ] && grep -q "bad.mtl:1" "$tmp/mf.txt.err" || fail "malformed MTL: fracture exit $c"
run "$tmp/md.txt" "$RUBBLE" decompose "$tmp/mtl/m.obj"
[ "$c" -eq 0 ] || fail "malformed MTL: decompose exit $c"
echo "adversarial.t.sh: ok"
