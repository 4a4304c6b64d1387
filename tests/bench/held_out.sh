#!/usr/bin/env bash
# The organic bench finds held-out meshes by name: per name the file whose stem is the name, else the shortest
# stem holding it (CGAL's data: elephant.off before elephant-with-holes.off, ChineseDragon-10kv.off).
set -eu
bench=$1
mesh=$2
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/meshes"
for name in elephant-with-holes elephant ChineseDragon-10kv; do cp "$mesh" "$tmp/meshes/$name.off"; done
"$bench" decomposition --organic --quick --held-out "$tmp/meshes" --methods qhull_hull --out "$tmp/out" \
    >"$tmp/log.txt"
for row in held_out_elephant held_out_ChineseDragon-10kv; do
    grep -q "^$row " "$tmp/log.txt" || { echo "no row $row:"; cat "$tmp/log.txt"; exit 1; }
done
if grep -q "elephant-with-holes" "$tmp/log.txt"; then
    echo "elephant-with-holes chosen:"
    cat "$tmp/log.txt"
    exit 1
fi
echo "held_out.sh: ok"
