#!/usr/bin/env bash
# `rubble-bench journal --out FILE` aborted on an uncaught filesystem_error (issue #35): a results folder that
# cannot be a folder is a usage error (exit 2) naming it, and nothing is written.
set -eu
bench=$1
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "a file" >"$tmp/file"
set +e
"$bench" journal --quick --out "$tmp/file" >"$tmp/out.txt" 2>"$tmp/err.txt"
c=$?
set -e
[ "$c" -eq 2 ] || { echo "journal --out FILE: exit $c, expected 2: $(cat "$tmp/err.txt")"; exit 1; }
grep -q -- "--out $tmp/file: exists and is not a folder" "$tmp/err.txt" || { cat "$tmp/err.txt"; exit 1; }
[ "$(cat "$tmp/file")" = "a file" ] || { echo "the file was changed"; exit 1; }
# The timed snapshot goes to the temporary folder, not to the results folder.
"$bench" journal --quick --out "$tmp/results" >/dev/null
[ -z "$(ls "$tmp/results" | grep -v '^journal\.\(csv\|png\)$' || true)" ] || { ls "$tmp/results"; exit 1; }
echo "journal_out.sh: ok"
