#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and runs each for a bounded time.
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET=60] [TARGET...]
# A crash leaves its input in build-fuzz/crashes/<target>/; minimise it (fuzz_<target> -minimize_crash=1) and
# add it to tests/corpus/<target>/ so that it stays a regression test (fuzz_replay_<target> in CTest).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(obj scene mesh_repair convex_clip)
dir=build-fuzz
if [ ! -f $dir/build.ninja ]; then
    CC=clang CXX=clang++ cmake -S . -B $dir -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRUBBLE_BUILD_FUZZERS=ON \
        -DRUBBLE_BUILD_TESTS=ON -DRUBBLE_BUILD_DEMO=OFF -DRUBBLE_BUILD_BULLET=OFF -DRUBBLE_BUILD_BENCH=OFF \
        -DRUBBLE_WERROR=OFF >/dev/null
else
    cmake $dir >/dev/null # pick up new targets
fi
status=0
for t in "${targets[@]}"; do
    if ! grep -q "fuzz/fuzz_$t:" $dir/build.ninja; then
        echo "fuzz: no target $t"; continue
    fi
    cmake --build $dir --target fuzz_$t -j "$(nproc)" >/dev/null
    work=$(mktemp -d)
    mkdir -p $dir/crashes/$t
    cp -r tests/corpus/$t/. "$work"/ 2>/dev/null || true
    echo "fuzz: $t for ${seconds}s"
    if ! $dir/fuzz/fuzz_$t "$work" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
        -artifact_prefix=$dir/crashes/$t/ -print_final_stats=1 2>$dir/fuzz_$t.log; then
        echo "fuzz: $t FAILED; see $dir/fuzz_$t.log and $dir/crashes/$t/"
        tail -40 $dir/fuzz_$t.log
        status=1
    else
        grep -E "stat::number_of_executed_units|cov:" $dir/fuzz_$t.log | tail -2
    fi
    rm -rf "$work"
done
exit $status
