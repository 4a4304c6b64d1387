#!/usr/bin/env bash
# Launches rubble-demo. Usage: scripts/demo-launch.sh BUILD_DIR [extra rubble-demo arguments]
#   DISPLAY set   → interactive window.
#   no DISPLAY    → headless autopilot for ${RUBBLE_DEMO_SECONDS:-20} s with EGL surfaceless rendering; if EGL is
#                   unavailable, the same run under xvfb-run. Output in ${RUBBLE_DEMO_OUT:-BUILD_DIR/demo-out}.
set -uo pipefail
build=${1:-build}
shift || true
demo="$build/bin/rubble-demo"
if [ -n "${DISPLAY:-}" ]; then
    echo "rubble-demo: opening the window (W/S pitch, A/D roll, Q/E yaw, Z/X speed, Space fire, P pause, Esc quit)"
    exec "$demo" "$@"
fi
seconds=${RUBBLE_DEMO_SECONDS:-20}
out=${RUBBLE_DEMO_OUT:-$build/demo-out}
rm -rf "$out"
mkdir -p "$out"
echo "rubble-demo: no DISPLAY, flying the ${seconds} s autopilot headless (EGL) ..."
if ! "$demo" --autopilot "$seconds" --screenshot-every 2 --out "$out" "$@"; then
    if command -v xvfb-run >/dev/null; then
        echo "rubble-demo: EGL run failed; retrying under xvfb-run" >&2
        xvfb-run -a -s "-screen 0 1280x720x24 -r" "$demo" --window --autopilot "$seconds" --screenshot-every 2 \
            --out "$out" "$@" || exit 1
    else
        exit 1
    fi
fi
echo
echo "Screenshots:   $(ls "$out"/shot_*.png 2>/dev/null | wc -l) PNGs in $out/ (shot_0001.png ...)"
echo "Timing report: $out/report.json (fps p50/p99, frame ms, impacts, fractures, latency p50/p99)"
echo "Per frame:     $out/frames.csv"
[ -f "$out/latency.csv" ] && echo "Per impact:    $out/latency.csv"
exit 0
