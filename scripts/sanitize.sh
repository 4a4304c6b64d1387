#!/usr/bin/env bash
# Sanitizer runs (clang). Usage: scripts/sanitize.sh [all|asan|tsan|fuzz|ci|configure-asan [DIR]|configure-tsan]
#   asan: the whole test suite built with ASan + UBSan into build-asan/ and run by CTest (every label but e2e,
#         which needs rubble-demo and Xvfb, and bench: the benches' smoke runs drive the library code the tests
#         reach, at ten times the cost; they run in make test); every finding is fatal
#         (-fno-sanitize-recover=all, halt_on_error). The libFuzzer targets are built into the same tree
#         (scripts/fuzz.sh uses it), so one tree serves both.
#   tsan: the threaded code, i.e. the runtime, Bullet-bridge, journal/snapshot and netplay tests (tests/runtime,
#         tests/bullet, tests/persist, tests/net), built with TSan into build-tsan/ and run by CTest; no benches
#         (robustness.md, 7).
#   fuzz: every libFuzzer target for a fixed seed and input count (scripts/fuzz.sh ci).
#   all:  asan, then tsan (`make sanitize`).  ci: asan, tsan, fuzz (`make sanitize-ci`, what .ci/run runs).
# Both trees are RelWithDebInfo with -gline-tables-only instead of -g (half the object size, file:line stack traces
# kept) and link with lld when it is installed (links 3x faster); -O1 compiled only 6 % faster but ran the tests
# and fuzzers 25-60 % slower (docs/robustness.md, section 7). They share ccache with every other tree, so a warm
# cache rebuilds only what changed.
# Environment: JOBS (default nproc), RUBBLE_STRESS_IMPACTS (default 300 here: ASan is ~10x slower),
# RUBBLE_SWEEP_SCALE (default 0.1: a tenth of the shatter sweep's CI slice).
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-all}
jobs=${JOBS:-$(nproc)}
flags="-O2 -gline-tables-only -DNDEBUG"
# No Python module: an instrumented extension cannot be loaded by an uninstrumented python3.
common=(-G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRUBBLE_BUILD_DEMO=OFF
    -DRUBBLE_BUILD_PYTHON=OFF
    -DRUBBLE_WERROR=OFF # warnings are enforced by the gcc build; clang only has to compile
    "-DCMAKE_C_FLAGS_RELWITHDEBINFO=$flags" "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$flags")
if command -v ld.lld >/dev/null; then
    common+=(-DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld -DCMAKE_SHARED_LINKER_FLAGS=-fuse-ld=lld)
fi

configure() { # dir, sanitizers, extra cmake args... (re-applied to an existing tree, so option changes reach it)
    local dir=$1 san=$2
    shift 2
    CC=clang CXX=clang++ cmake -S . -B "$dir" "${common[@]}" -DRUBBLE_SANITIZE="$san" "$@" >/dev/null
}

# The ASan + UBSan tree: fuzzers, no benches, no rubble-server (only its e2e test runs it).
asan_args=(address,undefined -DRUBBLE_BUILD_FUZZERS=ON -DRUBBLE_BUILD_BENCH=OFF -DRUBBLE_BUILD_SERVER=OFF)

elapsed() { echo "$(($(date +%s) - $1)) s"; }

asan() {
    local t0
    t0=$(date +%s)
    configure build-asan "${asan_args[@]}" || return 1
    cmake --build build-asan -j "$jobs" || return 1
    echo "sanitize: ASan+UBSan build took $(elapsed "$t0")"
    local status=0
    t0=$(date +%s)
    # Leak checking is on (ASan's default on Linux).
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1 \
        UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
        RUBBLE_STRESS_IMPACTS=${RUBBLE_STRESS_IMPACTS:-300} RUBBLE_SWEEP_SCALE=${RUBBLE_SWEEP_SCALE:-0.1} \
        ctest --test-dir build-asan --output-on-failure -j "$jobs" --timeout 1200 -LE e2e || status=1
    echo "sanitize: ASan+UBSan tests took $(elapsed "$t0")"
    return $status
}

tsan() {
    local t0
    t0=$(date +%s)
    configure build-tsan thread -DRUBBLE_BUILD_BENCH=OFF || return 1
    # Only the threaded code: the runtime's tests, the Bullet bridge (which drives DestructionWorld), the
    # journal/snapshot tests and netplay.
    local targets
    targets=$(ninja -C build-tsan -t targets all | sed -n 's#^tests/\(\(runtime\|bullet\|persist\|net\)_[A-Za-z]*_test\):.*#\1#p')
    # shellcheck disable=SC2086
    cmake --build build-tsan -j "$jobs" --target $targets || return 1
    echo "sanitize: TSan build took $(elapsed "$t0")"
    local status=0
    t0=$(date +%s)
    # Clang 14's TSan cannot map its shadow with the larger ASLR entropy of recent kernels: run without ASLR.
    local norand=()
    if [ "$(cat /proc/sys/vm/mmap_rnd_bits 2>/dev/null || echo 28)" -gt 28 ]; then norand=(setarch "$(uname -m)" -R); fi
    TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
        "${norand[@]}" ctest --test-dir build-tsan --output-on-failure -j "$jobs" --timeout 1200 \
        -L 'runtime|bullet|persist|net' || status=1
    echo "sanitize: TSan tests took $(elapsed "$t0")"
    return $status
}

fuzz() {
    local t0
    t0=$(date +%s)
    local status=0
    bash scripts/fuzz.sh ci || status=1
    echo "sanitize: fuzzing took $(elapsed "$t0")"
    return $status
}

# Runs every stage named, even after one failed; fails if any did (each stage returns its own status).
run() {
    local failed=()
    for stage in "$@"; do
        "$stage" || failed+=("$stage")
    done
    if [ ${#failed[@]} -gt 0 ]; then
        echo "sanitize: FAILED: ${failed[*]}" >&2
        return 1
    fi
}

case "$what" in
    all) run asan tsan ;;
    asan) run asan ;;
    tsan) run tsan ;;
    fuzz) run fuzz ;;
    ci) run asan tsan fuzz ;;
    configure-asan) configure "${2:-build-asan}" "${asan_args[@]}" ;;
    configure-tsan) configure build-tsan thread -DRUBBLE_BUILD_BENCH=OFF ;;
    *)
        echo "usage: scripts/sanitize.sh [all|asan|tsan|fuzz|ci|configure-asan [DIR]|configure-tsan]" >&2
        exit 2
        ;;
esac
