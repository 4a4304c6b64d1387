#!/usr/bin/env bash
# Hostile inputs to `rubble check` / `fracture` (issue #20): non-UTF-8 text in JSON, special files, glTF nesting,
# atomic repair output, stale staging folders, validation of options.
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
data="$root/tests/data/meshes"
# shellcheck source=tests/support/cli.sh
source "$root/tests/support/cli.sh"

# --- JSON output never aborts on bytes that are not UTF-8 ------------------------------------------------------
printf 'v 0 1 \xe9\nv 1 0 0\nv 0 0 1\nf 1 2 3\n' >"$tmp/latin1.obj"
run "$tmp/l.json" "$RUBBLE" check --json "$tmp/latin1.obj"
[ "$c" -eq 2 ] || fail "Latin-1 number: exit $c, expected 2"
json_ok "$tmp/l.json" "'\\\\xE9' in d['meshes'][0]['error']" || fail "Latin-1 number JSON: $(cat "$tmp/l.json")"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \xe9\n' >"$tmp/latin1_index.obj"
run "$tmp/li.json" "$RUBBLE" check --json "$tmp/latin1_index.obj"
[ "$c" -eq 2 ] && json_ok "$tmp/li.json" "'error' in d['meshes'][0]" || fail "Latin-1 index: $(cat "$tmp/li.json")"
# A valid cube under a non-UTF-8 name: check, fracture and batch fracture print JSON naming it escaped.
bad="$tmp/cube_$(printf '\xe9').obj"
cp "$data/cube.obj" "$bad"
cp "$data/cube.obj" "$tmp/other.obj"
"$RUBBLE" check --json "$bad" >"$tmp/n.json" || fail "check of the cube under a Latin-1 name failed"
json_ok "$tmp/n.json" "d['meshes'][0]['file'].endswith('cube_\\\\xE9.obj')" || fail "check name: $(cat "$tmp/n.json")"
"$RUBBLE" fracture "$bad" --impact 0.5,0.5,1 --impulse 200 -o "$tmp/f1" --json >"$tmp/f1.json" \
    || fail "fracture of the cube under a Latin-1 name failed"
json_ok "$tmp/f1.json" "len(d['pieces']) >= 2" || fail "fracture JSON: $(cat "$tmp/f1.json")"
"$RUBBLE" fracture "$bad" "$tmp/other.obj" --impact 0.5,0.5,1 --impulse 200 -o "$tmp/f2" --json >"$tmp/f2.json" \
    || fail "batch fracture with a Latin-1 name failed"
json_ok "$tmp/f2.json" "d['results'][0]['file'].endswith('cube_\\\\xE9.obj') and len(d['results']) == 2" \
    || fail "batch JSON: $(cat "$tmp/f2.json")"

# --- Regular files only -----------------------------------------------------------------------------------------
ln -s /dev/zero "$tmp/zero.obj"
mkfifo "$tmp/pipe.obj"
run "$tmp/z.json" timeout 20 "$RUBBLE" check --json "$tmp/zero.obj" "$tmp/pipe.obj"
[ "$c" -eq 2 ] || fail "/dev/zero and a FIFO: exit $c, expected 2: $(cat "$tmp/z.json.err")"
json_ok "$tmp/z.json" "'character device, not a regular file' in d['meshes'][0]['error'] and \
    'a FIFO, not a regular file' in d['meshes'][1]['error']" || fail "special files: $(cat "$tmp/z.json")"

# --- check --repair -o: colliding stems refused, failed writes leave no partial file and still print JSON ---------
mkdir -p "$tmp/a" "$tmp/b"
cp "$data/cube.obj" "$tmp/a/m.obj"
cp "$data/cube.off" "$tmp/b/m.off"
run "$tmp/col.txt" "$RUBBLE" check --repair -o "$tmp/rep" "$tmp/a/m.obj" "$tmp/b/m.off"
[ "$c" -eq 2 ] || fail "colliding stems: exit $c, expected 2"
grep -q "two inputs would be repaired into the same file" "$tmp/col.txt.err" || fail "stems: $(cat "$tmp/col.txt.err")"
[ ! -e "$tmp/rep/m.obj" ] || fail "colliding stems: something was written"
# A 4 KiB file size limit (SIGXFSZ ignored): the 10,092-triangle cube cannot be written, the tetrahedron can.
mkdir -p "$tmp/rep"
echo "old" >"$tmp/rep/cube_10092.obj"
set +e
(trap '' XFSZ; ulimit -f 4; exec "$RUBBLE" check --json --repair -o "$tmp/rep" "$root/assets/models/cube_10092.obj" \
    "$data/tetra.obj" >"$tmp/full.json" 2>"$tmp/full.err")
c=$?
set -e
[ "$c" -eq 2 ] || fail "failed write: exit $c, expected 2: $(cat "$tmp/full.err")"
json_ok "$tmp/full.json" "'write failed: File too large' in d['meshes'][0]['error'] and d['meshes'][1]['valid']" \
    || fail "failed write JSON: $(cat "$tmp/full.json")"
[ "$(cat "$tmp/rep/cube_10092.obj")" = old ] || fail "failed write replaced the previous file"
[ -z "$(ls -A "$tmp/rep" | grep rubble-tmp || true)" ] || fail "failed write left $(ls -A "$tmp/rep")"
"$RUBBLE" check "$tmp/rep/tetra.obj" >/dev/null || fail "the tetrahedron was not written"

# --- Staging folders of killed runs are removed; those of live processes are kept ------------------------------
sleep 0 & dead=$!
wait $dead
mkdir -p "$tmp/stale/.out.rubble-tmp-$dead/sub" "$tmp/stale/.out.rubble-tmp-$$"
"$RUBBLE" fracture "$data/cube.obj" --impact 0.5,0.5,1 --impulse 200 -o "$tmp/stale/out" >/dev/null \
    || fail "fracture next to stale staging folders failed"
[ ! -e "$tmp/stale/.out.rubble-tmp-$dead" ] || fail "the stale staging folder of PID $dead was not removed"
[ -d "$tmp/stale/.out.rubble-tmp-$$" ] || fail "the staging folder of a live process was removed"
[ -n "$(ls "$tmp/stale/out")" ] || fail "no pieces written"

# --- Messages and validation -------------------------------------------------------------------------------------
for seed in -1 18446744073709551616 1e3; do
    run "$tmp/seed.txt" "$RUBBLE" fracture "$data/cube.obj" --impact 0.5,0.5,1 --seed "$seed" -o "$tmp/seed"
    [ "$c" -eq 2 ] || fail "--seed $seed: exit $c, expected 2"
    grep -qF "seed must be a whole number in [0, 18446744073709551615], got " "$tmp/seed.txt.err" \
        || fail "--seed $seed message"
done
"$RUBBLE" fracture "$data/cube.obj" --impact 0.5,0.5,1 --seed 18446744073709551615 -o "$tmp/seedmax" >/dev/null \
    || fail "--seed 2^64-1 should be accepted"
run "$tmp/nan.txt" "$RUBBLE" fracture "$data/cube.obj" --impact 0.5,0.5,1 --impulse nan -o "$tmp/nan"
[ "$c" -eq 2 ] && grep -qF "impulse must be a finite number in [0, 1e+12], got nan" "$tmp/nan.txt.err" \
    || fail "--impulse nan: exit $c"
run "$tmp/cnan.txt" "$RUBBLE" decompose "$data/cube.obj" --concavity nan
[ "$c" -eq 2 ] && grep -q "'nan' is not a finite number" "$tmp/cnan.txt.err" || fail "--concavity nan: exit $c"
# A mesh smaller than the smallest cell: one piece, the input itself, and the output says so.
awk '/^v /{printf "v %.17g %.17g %.17g\n", $2*0.001, $3*0.001, $4*0.001; next} {print}' "$data/cube.obj" >"$tmp/tiny.obj"
run "$tmp/tiny.json" "$RUBBLE" fracture "$tmp/tiny.obj" --impact 0.0005,0.0005,0.001 -o "$tmp/tiny" --json
[ "$c" -eq 0 ] || fail "tiny cube: exit $c"
json_ok "$tmp/tiny.json" "d['cut'] is False and d['dropped_volume'] == 0 and len(d['pieces']) == 1" \
    || fail "tiny cube JSON: $(cat "$tmp/tiny.json")"
grep -q "nothing was cut" "$tmp/tiny.json.err" || fail "tiny cube: no 'nothing was cut' on stderr"
# A cube scaled by 1e300 overflows; check --json says valid false and lists the problem.
awk '/^v /{printf "v %s %s %s\n", $2*1e300, $3*1e300, $4*1e300; next} {print}' "$data/cube.obj" >"$tmp/huge.obj"
run "$tmp/huge.json" "$RUBBLE" check --json "$tmp/huge.obj"
[ "$c" -eq 1 ] || fail "1e300 cube: exit $c"
json_ok "$tmp/huge.json" "d['meshes'][0]['valid'] is False and d['meshes'][0]['problems'] == \
    [\"7 vertices have a coordinate beyond ±1e+50, the bound that keeps the volume integrals finite (e.g. vertex 1 \
at 1e+300, vertex 2 at 1e+300, vertex 3 at 1e+300); scale the mesh down\"]" \
    || fail "1e300 cube JSON: $(cat "$tmp/huge.json")"
"$RUBBLE" check --json "$data/cube.obj" >"$tmp/valid.json"
json_ok "$tmp/valid.json" "d['meshes'][0]['valid'] is True and d['meshes'][0]['problems'] == []" \
    || fail "valid cube JSON: $(cat "$tmp/valid.json")"

exit 0
