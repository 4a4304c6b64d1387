#!/usr/bin/env bash
# Fails when a tracked C++ file differs from .clang-format's output (run `make format` to fix).
set -euo pipefail
cd "$(dirname "$0")/.."
files=$( (git ls-files '*.cpp' '*.hpp'; git ls-files --others --exclude-standard '*.cpp' '*.hpp') | sort -u)
[ -n "$files" ] || exit 0
bad=()
for f in $files; do
    [ -f "$f" ] || continue
    if ! clang-format --dry-run --Werror "$f" >/dev/null 2>&1; then bad+=("$f"); fi
done
if [ ${#bad[@]} -gt 0 ]; then
    echo "check-format: these files need clang-format (make format):" >&2
    printf '  %s\n' "${bad[@]}" >&2
    exit 1
fi
echo "check-format: ok ($(echo "$files" | wc -l) files)"
