#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and runs each for a bounded time.
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET=60] [TARGET...]
# The fuzzers live in the ASan tree of scripts/sanitize.sh (build-asan/, or $RUBBLE_FUZZ_DIR), so `make sanitize`
# and `make fuzz-smoke` share one build. A crash leaves its input in <tree>/crashes/<target>/; minimise it
# (fuzz_<target> -minimize_crash=1 -runs=10000 FILE) and add it to tests/corpus/<target>/ so that it stays a
# regression test (fuzz_replay_<target> in CTest). Inputs that grew the coverage stay in <tree>/corpus/<target>/
# for the next run; the repository's corpus is only read.
# Environment: RUBBLE_FUZZ_SEED and RUBBLE_FUZZ_RUNS make a run reproducible (libFuzzer's -seed and -runs; the
# time limit still caps it). CI sets both, so a finding there is found again locally by the same command.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(obj scene mesh_repair convex_clip fracture)
dir=${RUBBLE_FUZZ_DIR:-build-asan}
if [ ! -f $dir/build.ninja ]; then
    if [ "$dir" = build-asan ]; then bash scripts/sanitize.sh configure-asan; else
        CC=clang CXX=clang++ cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRUBBLE_BUILD_DEMO=OFF \
            -DRUBBLE_BUILD_BENCH=OFF -DRUBBLE_WERROR=OFF -DRUBBLE_SANITIZE=address,undefined -DRUBBLE_BUILD_FUZZERS=ON >/dev/null
    fi
else
    cmake $dir >/dev/null # pick up new targets
fi
status=0
for t in "${targets[@]}"; do
    if ! grep -q "fuzz/fuzz_$t:" $dir/build.ninja; then
        echo "fuzz: no target fuzz_$t in $dir (configured without -DRUBBLE_BUILD_FUZZERS=ON?)"
        status=1
        continue
    fi
    cmake --build $dir --target fuzz_$t -j "$(nproc)" >/dev/null
    work=$dir/corpus/$t
    mkdir -p $dir/crashes/$t "$work"
    echo "fuzz: $t for ${seconds}s"
    repro=()
    [ -z "${RUBBLE_FUZZ_SEED:-}" ] || repro+=(-seed="$RUBBLE_FUZZ_SEED")
    [ -z "${RUBBLE_FUZZ_RUNS:-}" ] || repro+=(-runs="$RUBBLE_FUZZ_RUNS")
    if ! $dir/fuzz/fuzz_$t "$work" tests/corpus/$t -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
        "${repro[@]}" -artifact_prefix=$dir/crashes/$t/ -print_final_stats=1 2>$dir/fuzz_$t.log; then
        echo "fuzz: $t FAILED; see $dir/fuzz_$t.log and $dir/crashes/$t/"
        tail -40 $dir/fuzz_$t.log
        status=1
    else
        grep -E "stat::number_of_executed_units|cov:" $dir/fuzz_$t.log | tail -2
    fi
done
exit $status
