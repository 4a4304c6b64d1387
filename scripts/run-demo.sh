#!/usr/bin/env bash
# `make demo`: runs rubble-demo from the build folder given as $1 (default build).
# With a DISPLAY it opens the game window; without one it flies the 20 s autopilot headless (EGL) and prints
# where the screenshots and the timing report are.
set -euo pipefail
build=${1:-build}
cd "$(dirname "$0")/.."
if [ ! -x "$build/bin/rubble-demo" ]; then
    echo "make demo: $build/bin/rubble-demo is not built (is RUBBLE_BUILD_DEMO off, or did the build fail?)" >&2
    exit 1
fi
exec bash scripts/demo-launch.sh "$build"
