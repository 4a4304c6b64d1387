#!/usr/bin/env bash
# Runs the benchmark suites of a built tree and writes their results into bench/results/ (CSV + PNG).
# Usage: scripts/run-bench.sh BUILD_DIR   (called by `make bench` with the Release tree)
# Extra arguments after BUILD_DIR are passed to the decomposition, booleans and impact suites (e.g. --runs 5,
# --quick); RUBBLE_BENCH_RESULTS=DIR writes somewhere else than bench/results/ (e.g. for a trial run);
# RUBBLE_SCENE_SECONDS sets the length of each scene run (default 60; scripts/scene-bench.sh).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/scripts/bench-lib.sh"
build="${1:?usage: scripts/run-bench.sh BUILD_DIR [suite options]}"
shift
bench="$build/bin/rubble-bench"
need_binary run-bench "$bench" "make release"

status=0
echo "== decomposition"
"$bench" decomposition --out "$results" "$@" || status=1
echo
echo "== booleans"
"$bench" booleans --out "$results" "$@" || status=1
echo
echo "== impact"
"$bench" impact --out "$results" "$@" || status=1
echo
echo "== structure"
"$bench" structure --out "$results" "$@" || status=1
if "$bench" --help 2>/dev/null | grep -qE '^ +scene( |$)'; then
    echo
    echo "== scenes (${RUBBLE_SCENE_SECONDS:-60} s each)"
    RUBBLE_BENCH_RESULTS="$results" bash "$root/scripts/scene-bench.sh" "$build" "${RUBBLE_SCENE_SECONDS:-60}" ||
        status=1
else
    echo "(rubble-bench has no scene suite in this build: skipped)"
fi
echo
echo "results: $results"
ls -1 "$results"
exit $status
