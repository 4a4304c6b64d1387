#!/usr/bin/env bash
# The shipped models are valid solids, and scripts/make-assets.py still verifies them (without rewriting).
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
fail() { echo "assets.t.sh: $*"; exit 1; }
out="$("$RUBBLE" check "$root"/assets/models/*.obj 2>&1)" || fail "rubble check rejects a model: $out"
[ "$(grep -c ': valid$' <<<"$out")" -eq "$(ls "$root"/assets/models/*.obj | wc -l)" ] || fail "not every model valid"
out="$(python3 "$root/scripts/make-assets.py" --check-only 2>&1)" || fail "make-assets.py --check-only: $out"
exit 0
