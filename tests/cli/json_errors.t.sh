#!/usr/bin/env bash
# --json always prints a result object: `rubble fracture` on an invalid mesh, a bad option or a failed write, and
# `rubble decompose` on an unreadable mesh or a failed write (issue #35).
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
data="$root/tests/data/meshes"
# shellcheck source=tests/support/cli.sh
source "$root/tests/support/cli.sh"

# An open mesh is refused (exit 2) with the reason in {"error"}.
grep -v "^f 1 2 6 5" "$data/open_cube.obj" >"$tmp/open2.obj"
run "$tmp/open.json" "$RUBBLE" fracture "$tmp/open2.obj" --impact 0.5,0.5,1 -o "$tmp/o" --json
[ "$c" -eq 2 ] || fail "open mesh: exit $c, expected 2"
json_ok "$tmp/open.json" "'not a valid solid' in d['error']" || fail "open mesh JSON: '$(cat "$tmp/open.json")'"
# A missing required option: CLI11's message in {"error"}.
run "$tmp/usage.json" "$RUBBLE" fracture "$data/cube.obj" -o "$tmp/u" --json
[ "$c" -eq 2 ] || fail "no --impact: exit $c, expected 2"
json_ok "$tmp/usage.json" "'--impact' in d['error']" || fail "no --impact JSON: '$(cat "$tmp/usage.json")'"
# A write that fails (a 4 KiB file size limit): exit 1, the results with "error".
set +e
(trap '' XFSZ; ulimit -f 4; exec "$RUBBLE" fracture "$root/assets/models/cube_588.obj" --impact 0.9,0.2,-0.1 \
    --impulse 400 -o "$tmp/w" --json >"$tmp/write.json" 2>"$tmp/write.err")
c=$?
set -e
[ "$c" -eq 1 ] || fail "failed write: exit $c, expected 1: $(cat "$tmp/write.err")"
json_ok "$tmp/write.json" "'File too large' in d['error'] and len(d['pieces']) >= 2" \
    || fail "failed write JSON: '$(cat "$tmp/write.json")'"
[ ! -e "$tmp/w" ] || fail "failed write left $tmp/w"

# decompose: an unreadable mesh (exit 2) and a failed write of the parts (exit 1).
run "$tmp/d.json" "$RUBBLE" decompose "$tmp/missing.obj" --json
[ "$c" -eq 2 ] || fail "decompose of a missing file: exit $c, expected 2"
json_ok "$tmp/d.json" "d['file'].endswith('missing.obj') and 'missing.obj' in d['error']" \
    || fail "decompose missing JSON: '$(cat "$tmp/d.json")'"
run "$tmp/dw.json" "$RUBBLE" decompose "$data/cube.obj" -o "$tmp/no/such/dir/parts.json" --json
[ "$c" -eq 1 ] || fail "decompose with an unwritable -o: exit $c, expected 1"
json_ok "$tmp/dw.json" "'error' in d" || fail "decompose write JSON: '$(cat "$tmp/dw.json")'"
exit 0
