#!/usr/bin/env bash
# Unpacks CGAL's data meshes (armadillo, camel, elephant, Chinese dragon, bunny, cow, homer) from Debian's
# libcgal-demo package into DIR, for `rubble-bench decomposition --organic --held-out DIR`. Nothing is installed
# and nothing goes into the repository. Usage: bench/held-out-meshes.sh DIR
set -eu
dir=${1:?usage: $0 DIR}
mkdir -p "$dir"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
(cd "$work" && apt-get download libcgal-demo >/dev/null 2>"$work/apt.err") || { cat "$work/apt.err" >&2; exit 1; }
dpkg-deb -x "$work"/libcgal-demo_*.deb "$work/pkg"
names="armadillo camel elephant ChineseDragon-10kv bunny00 cow homer"
members=""
for n in $names; do members="$members data/meshes/$n.off"; done
# shellcheck disable=SC2086
tar -xzf "$work/pkg/usr/share/doc/libcgal-dev/data.tar.gz" -C "$work" $members
for n in $names; do mv "$work/data/meshes/$n.off" "$dir/"; done
echo "held-out meshes in $dir: $names"
