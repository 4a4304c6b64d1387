#!/usr/bin/env bash
# Runs every tests/cli/*.t.sh script against the real `rubble` binary ($RUBBLE). Each script exits non-zero on failure.
set -u
dir=$(cd "$(dirname "$0")" && pwd)
fail=0
shopt -s nullglob
for t in "$dir"/*.t.sh; do
    if bash "$t"; then echo "ok   $(basename "$t")"; else echo "FAIL $(basename "$t")"; fail=1; fi
done
exit $fail
