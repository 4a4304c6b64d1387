#!/usr/bin/env bash
# `rubble check` on the thesis's models: all nine seed OBJ files are valid solids (verified by hand, see
# docs/robustness.md). Skips when the seed media folder is absent (as in a user's clone).
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
media="${RUBBLE_SEED_MEDIA:-$root/../shared/seed/media}"
if [ ! -d "$media" ]; then
    echo "check_seed.t.sh: skipped ($media is absent)"
    exit 0
fi
out="$("$RUBBLE" check --json "$media"/*.obj)" || { echo "check_seed.t.sh: expected every seed model to be valid"; exit 1; }
echo "$out" | python3 -c '
import json, sys
d = json.load(sys.stdin)
names = sorted(m["file"].rsplit("/", 1)[-1] for m in d["meshes"])
expected = ["building.obj", "cube_10092.obj", "cube_108.obj", "cube_12.obj", "cube_2700.obj", "cube_588.obj",
            "empty.obj", "missile.obj", "ship.obj"]
assert names == expected, names
for m in d["meshes"]:
    assert m["closed"] and m["manifold"] and m["oriented"] and m["self_intersections"] == 0, m
    assert m["volume"] > 0, m
' || { echo "check_seed.t.sh: unexpected verdicts: $out"; exit 1; }
