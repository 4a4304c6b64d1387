#!/usr/bin/env bash
# Runs the demo; until rubble-demo exists, runs the CLI on a shipped sample and says so.
set -euo pipefail
build=${1:-build}
cd "$(dirname "$0")/.."
if [ -x "$build/bin/rubble-demo" ]; then
    exec bash scripts/demo-launch.sh "$build"
fi
echo "make demo: rubble-demo is not built yet; running the CLI on a shipped sample instead."
"$build/bin/rubble" --version
