#!/usr/bin/env bash
# Runs examples/hello (HELLO) and checks that docs/hello.md (DOC) shows its output as it is: the unlabelled code
# blocks that start with "piece " or "object " are, in order, exactly what the program prints (timings aside).
set -euo pipefail
hello=$1 doc=$2
normalize() { sed -E 's/in [0-9.]+ ms/in N ms/'; }
printed=$("$hello" | normalize)
shown=$(awk '/^```/ { if (inside) { inside = 0; keep = 0 } else { inside = 1; first = 1; plain = ($0 == "```") }; next }
             inside && first { keep = plain && ($0 ~ /^(piece|object) /); first = 0 }
             inside && keep { print }' "$doc" | normalize)
if [ "$printed" != "$shown" ]; then
    echo "docs/hello.md does not show what examples/hello prints:" >&2
    diff <(echo "$shown") <(echo "$printed") >&2 || true
    exit 1
fi
echo "docs/hello.md shows the output of examples/hello"
