#!/usr/bin/env bash
# `rubble check`: verdicts, JSON fields, exit codes (0 valid, 1 invalid, 2 unreadable) and --repair.
set -eu
data="$(cd "$(dirname "$0")/../data/meshes" && pwd)"
# shellcheck source=tests/support/cli.sh
source "$(dirname "$0")/../support/cli.sh"

# A valid cube: exit 0, text and JSON verdicts.
"$RUBBLE" check "$data/cube.obj" >"$tmp/out.txt" || fail "valid cube should exit 0"
grep -q "cube.obj: valid" "$tmp/out.txt" || fail "missing verdict: $(cat "$tmp/out.txt")"
grep -q "volume              1$" "$tmp/out.txt" || fail "missing volume"
"$RUBBLE" check --json "$data/cube.obj" >"$tmp/out.json" || fail "valid cube --json should exit 0"
for field in '"file"' '"vertices":8' '"triangles":12' '"closed":true' '"manifold":true' '"oriented":true' \
    '"self_intersections":0' '"volume":1.0' '"center_of_mass":[0.5,0.5,0.5]' '"bbox":[[0.0,0.0,0.0],[1.0,1.0,1.0]]'; do
    grep -qF "$field" "$tmp/out.json" || fail "JSON lacks $field: $(cat "$tmp/out.json")"
done
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert len(d['meshes'])==1" "$tmp/out.json" \
    || fail "JSON does not parse"
"$RUBBLE" check --json --no-self-intersections "$data/cube.obj" | grep -qF '"self_intersections":null' \
    || fail "--no-self-intersections should give null"

# A broken (open) mesh: exit 1, says what is wrong and how to repair.
set +e
"$RUBBLE" check "$data/open_cube.obj" >"$tmp/open.txt" 2>&1; code=$?
set -e
[ "$code" -eq 1 ] || fail "open cube should exit 1, got $code"
grep -q "not closed" "$tmp/open.txt" || fail "open cube: no 'not closed' in: $(cat "$tmp/open.txt")"
grep -q "rubble check --repair -o OUT" "$tmp/open.txt" || fail "open cube: no repair hint"

# Garbage: exit 2 with the file name (and line) in the message.
set +e
"$RUBBLE" check "$data/garbage.obj" >"$tmp/garbage.txt" 2>&1; code=$?
set -e
[ "$code" -eq 2 ] || fail "garbage should exit 2, got $code"
grep -q "garbage.obj:1: " "$tmp/garbage.txt" || fail "garbage: message lacks file:line: $(cat "$tmp/garbage.txt")"
set +e
"$RUBBLE" check "$data/huge_claim.stl" >"$tmp/huge.txt" 2>&1; code=$?
set -e
[ "$code" -eq 2 ] || fail "huge STL claim should exit 2, got $code"
grep -q "huge_claim.stl: binary STL header claims 2000000000 triangles" "$tmp/huge.txt" || fail "huge STL message"

# Several files: the worst exit code wins, JSON lists every file.
set +e
"$RUBBLE" check --json "$data/cube.obj" "$data/open_cube.obj" "$data/garbage.obj" >"$tmp/all.json" 2>/dev/null; code=$?
set -e
[ "$code" -eq 2 ] || fail "mixed files should exit 2, got $code"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert len(d['meshes'])==3 and 'error' in d['meshes'][2]" \
    "$tmp/all.json" || fail "mixed JSON: $(cat "$tmp/all.json")"

# --repair turns a cube with a flipped face into a valid cube.
"$RUBBLE" check --repair -o "$tmp/fixed.obj" "$data/flipped_face_cube.obj" >"$tmp/repair.txt" \
    || fail "repair of the flipped cube should exit 0: $(cat "$tmp/repair.txt")"
grep -q "flipped" "$tmp/repair.txt" || fail "repair report does not say what was fixed"
"$RUBBLE" check "$tmp/fixed.obj" >/dev/null || fail "repaired output is not valid"
"$RUBBLE" check --json "$tmp/fixed.obj" | grep -qF '"volume":1.0' || fail "repaired volume is not 1"

# --repair closes a planar hole: the open cube becomes the unit cube.
"$RUBBLE" check --repair -o "$tmp/open_fixed.obj" "$data/open_cube.obj" >"$tmp/repair_open.txt" 2>&1 \
    || fail "repair of the open cube should exit 0: $(cat "$tmp/repair_open.txt")"
grep -q "closed 1 hole" "$tmp/repair_open.txt" || fail "open repair: no 'closed 1 hole'"
"$RUBBLE" check --json "$tmp/open_fixed.obj" | grep -qF '"volume":1.0' || fail "closed cube's volume is not 1"

# A hole bent at a right angle (top and front faces missing) cannot be closed: exit 1, says what to do, and
# writes nothing (also with --json, which reports "written": false).
grep -v "^f 1 2 6 5" "$data/open_cube.obj" >"$tmp/open2.obj"
set +e
"$RUBBLE" check --repair -o "$tmp/open2_fixed.obj" "$tmp/open2.obj" >"$tmp/repair_open2.txt" 2>&1; code=$?
set -e
[ "$code" -eq 1 ] || fail "repair of the twice-open cube should exit 1, got $code"
grep -q "could not repair" "$tmp/repair_open2.txt" || fail "open repair: no 'could not repair'"
grep -q "Remesh modifier" "$tmp/repair_open2.txt" || fail "open repair: does not say what the user can do"
[ ! -e "$tmp/open2_fixed.obj" ] || fail "an unrepaired mesh was written"
set +e
"$RUBBLE" check --json --repair -o "$tmp/open2_fixed.obj" "$tmp/open2.obj" >"$tmp/repair_open2.json" 2>/dev/null
code=$?
set -e
[ "$code" -eq 1 ] || fail "--json repair of the twice-open cube should exit 1, got $code"
python3 -c 'import json,sys; m=json.load(open(sys.argv[1]))["meshes"][0]; assert m["written"] is False and m["valid"] is False, m' \
    "$tmp/repair_open2.json" || fail "--json repair: $(cat "$tmp/repair_open2.json")"
[ ! -e "$tmp/open2_fixed.obj" ] || fail "an unrepaired mesh was written (--json)"

# Usage errors exit 2.
set +e
"$RUBBLE" check --repair "$data/cube.obj" >/dev/null 2>&1; code=$?
set -e
[ "$code" -eq 2 ] || fail "--repair without -o should exit 2, got $code"
set +e
"$RUBBLE" check --repair -o "$tmp/x.stl" "$data/cube.obj" >/dev/null 2>&1; code=$?
set -e
[ "$code" -eq 2 ] || fail "non-.obj output should exit 2, got $code"
exit 0
