#!/usr/bin/env bash
# `rubble --version` answers and a missing subcommand is a usage error (exit 2).
set -eu
"$RUBBLE" --version | grep -q "rubble 0.1.0"
set +e
"$RUBBLE" >/dev/null 2>&1; code=$?
set -e
[ "$code" -eq 2 ] || { echo "expected exit 2 without a subcommand, got $code"; exit 1; }
