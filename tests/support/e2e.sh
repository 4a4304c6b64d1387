# Sourced by the demo's e2e scripts: a work folder, cleanup, fail(), a private Xvfb display and the stats
# helpers. The caller sets demo_pid when it starts rubble-demo (log in $work/log).
# Usage: source e2e.sh PREFIX LOG_LINES   (PREFIX names the work folder; LOG_LINES of the log on failure)

work=$(mktemp -d "/tmp/${1:?e2e.sh needs a prefix}.XXXXXX")
e2e_log_lines=${2:-20}
xvfb_pid=""
demo_pid=""
e2e_cleanup() {
    [ -n "$demo_pid" ] && kill "$demo_pid" 2>/dev/null
    [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null
    wait 2>/dev/null
    rm -rf "$work"
}
trap e2e_cleanup EXIT

fail() {
    echo "FAIL: $*"
    echo "--- demo output (last $e2e_log_lines lines) ---"
    tail -n "$e2e_log_lines" "$work/log" 2>/dev/null
    exit 1
}

# start_xvfb FIRST LAST XVFB_ARGS...: Xvfb on the first free display number in FIRST..LAST; exports DISPLAY.
start_xvfb() {
    local first=$1 last=$2 n
    shift 2
    disp=""
    for n in $(seq "$first" "$last"); do
        if [ ! -e "/tmp/.X11-unix/X$n" ] && [ ! -e "/tmp/.X$n-lock" ]; then
            disp=":$n"
            break
        fi
    done
    [ -n "$disp" ] || fail "no free X display number"
    Xvfb "$disp" "$@" -nolisten tcp >"$work/xvfb.log" 2>&1 &
    xvfb_pid=$!
    for _ in $(seq 1 100); do
        [ -e "/tmp/.X11-unix/X${disp#:}" ] && break
        sleep 0.1
    done
    [ -e "/tmp/.X11-unix/X${disp#:}" ] || fail "Xvfb did not start on $disp"
    export DISPLAY=$disp
}

# Last value of a field (frame, shots, impacts, paused, ...) in the stats lines.
field() { grep '^stats ' "$work/log" | tail -n 1 | tr ' ' '\n' | grep "^$1=" | cut -d= -f2; }

# wait_for SECONDS COMMAND...: polls until COMMAND succeeds; fails when the demo exits first.
wait_for() {
    local limit=$1
    shift
    for _ in $(seq 1 $((limit * 10))); do
        if "$@"; then return 0; fi
        kill -0 "$demo_pid" 2>/dev/null || fail "rubble-demo exited early"
        sleep 0.1
    done
    return 1
}

have_stats() { grep -q '^stats ' "$work/log"; }

# wait_exit SECONDS: waits for rubble-demo to quit and reaps it; 1 when it is still running after SECONDS.
wait_exit() {
    for _ in $(seq 1 $(($1 * 10))); do
        kill -0 "$demo_pid" 2>/dev/null || break
        sleep 0.1
    done
    kill -0 "$demo_pid" 2>/dev/null && return 1
    wait "$demo_pid" 2>/dev/null
    demo_pid=""
}
