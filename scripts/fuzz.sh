#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and runs each for a bounded time.
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET=60] [TARGET...]   exploration: random seeds, the corpus grows
#        scripts/fuzz.sh ci [TARGET...]                          CI: a fixed seed and input count per target
# The fuzzers live in the ASan tree of scripts/sanitize.sh (build-asan/, or $RUBBLE_FUZZ_DIR), so `make sanitize`
# and `make fuzz-smoke` share one build. A crash leaves its input in <tree>/crashes/<target>/; minimise it
# (fuzz_<target> -minimize_crash=1 -runs=10000 FILE) and add it to tests/corpus/<target>/ so that it stays a
# regression test (fuzz_replay_<target> in CTest).
# Exploration keeps the inputs that grew the coverage in <tree>/corpus/<target>/ for the next run (the repository's
# corpus is only read). RUBBLE_FUZZ_SEED and RUBBLE_FUZZ_RUNS (libFuzzer's -seed and -runs; the time limit still
# caps the run) make it reproducible.
# CI mode runs each target from seed 1 for the input count in ci_runs below (sized to 3-25 s each on the
# 2-core CI machine), starting from the repository's corpus and an empty work corpus (<tree>/corpus-ci/), with
# ASLR off, a fixed environment and libFuzzer's timed corpus reload off: otherwise two runs of the same seed
# diverge after a few hundred inputs (the targets' coverage depends on addresses, heap and stack, and reloads
# depend on time). So a CI run is one fixed input sequence, and `scripts/fuzz.sh ci TARGET` repeats it with the
# same build in any clone.
# ci_cap seconds bound each target on a loaded machine; a capped run is the same sequence cut short. A failing
# input is also printed in base64, so it can be taken from the CI log.
set -euo pipefail
cd "$(dirname "$0")/.."
declare -A ci_runs=([obj]=300000 [json]=300000 [off]=150000 [ply_stl]=180000 [scene]=250000 [mesh_repair]=25000 [convex_clip]=9000 [fracture]=500 [snapshot]=40000 [net_protocol]=100000 [mtl]=200000 [gltf]=40000)
ci_cap=150
# Seconds one input may run before it counts as a hang (CI: generous, for a loaded machine).
input_timeout=10
ci=0
if [ "${1:-}" = ci ]; then
    ci=1
    seconds=$ci_cap
    input_timeout=60
else
    seconds=${1:-60}
fi
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(obj json off ply_stl scene mesh_repair convex_clip fracture snapshot net_protocol mtl gltf)
dir=${RUBBLE_FUZZ_DIR:-build-asan}
if [ ! -f "$dir/build.ninja" ]; then
    bash scripts/sanitize.sh configure-asan "$dir"
else
    cmake "$dir" >/dev/null # pick up new targets
fi
# Every target is built first, then run JOBS at a time; summaries print in target order.
built=()
status=0
for t in "${targets[@]}"; do
    if grep -q "fuzz/fuzz_$t:" "$dir/build.ninja"; then
        built+=("$t")
    else
        echo "fuzz: no target fuzz_$t in $dir (configured without -DRUBBLE_BUILD_FUZZERS=ON?)"
        status=1
    fi
done
[ ${#built[@]} -eq 0 ] || cmake --build "$dir" -j "${JOBS:-$(nproc)}" --target "${built[@]/#/fuzz_}" >/dev/null

run_one() { # target; prints its summary, returns non-zero on a finding
    local t=$1 work t0 runs cov
    local repro=() norand=()
    if [ $ci = 1 ]; then
        work=$dir/corpus-ci/$t
        rm -rf "$work"
        repro=(-seed=1 -runs="${ci_runs[$t]}" -reload=0)
        # A fixed, minimal environment too: with ASLR off, the stack's addresses still move with its size.
        norand=(env -i PATH=/usr/bin:/bin)
        if setarch "$(uname -m)" -R true 2>/dev/null; then norand+=(setarch "$(uname -m)" -R); fi
        echo "fuzz: $t, seed 1, ${ci_runs[$t]} inputs (at most ${seconds}s)"
    else
        work=$dir/corpus/$t
        [ -z "${RUBBLE_FUZZ_SEED:-}" ] || repro+=(-seed="$RUBBLE_FUZZ_SEED")
        [ -z "${RUBBLE_FUZZ_RUNS:-}" ] || repro+=(-runs="$RUBBLE_FUZZ_RUNS")
        echo "fuzz: $t for ${seconds}s"
    fi
    mkdir -p "$dir/crashes/$t" "$work"
    t0=$(date +%s)
    if ! "${norand[@]}" "$dir/fuzz/fuzz_$t" "$work" "tests/corpus/$t" -max_total_time="$seconds" -timeout=$input_timeout -rss_limit_mb=2048 \
        -max_len=4096 "${repro[@]}" -artifact_prefix="$dir/crashes/$t/" -print_final_stats=1 2>"$dir/fuzz_$t.log"; then
        echo "fuzz: $t FAILED; see $dir/fuzz_$t.log and $dir/crashes/$t/"
        tail -40 "$dir/fuzz_$t.log"
        find "$dir/crashes/$t" -type f -newermt "@$t0" | while read -r f; do
            echo "fuzz: $f (base64): $(base64 -w0 "$f")"
        done
        return 1
    fi
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/fuzz_$t.log")
    cov=$(grep -o 'cov: [0-9]*' "$dir/fuzz_$t.log" | tail -1)
    echo "fuzz: $t ok, $runs inputs in $(($(date +%s) - t0)) s, $cov"
}

slots=${JOBS:-$(nproc)}
mkdir -p "$dir/fuzz-out"
pids=()
for t in "${built[@]}"; do
    while [ "$(jobs -rp | wc -l)" -ge "$slots" ]; do wait -n || true; done
    run_one "$t" >"$dir/fuzz-out/$t.txt" 2>&1 &
    pids+=("$!:$t")
done
for p in "${pids[@]}"; do
    if ! wait "${p%%:*}"; then status=1; fi
    cat "$dir/fuzz-out/${p#*:}.txt"
done
exit $status
