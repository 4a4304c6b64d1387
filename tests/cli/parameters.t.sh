#!/usr/bin/env bash
# The CLI face of the shared parameter table (tests/data/parameter_cases.tsv): `rubble fracture` exits 2 with
# the table's message on stderr and, with --json, in {"error"} on stdout, writing nothing; values marked ok
# are accepted.
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
cube="$root/tests/data/meshes/cube.obj"
# shellcheck source=tests/support/cli.sh
source "$(dirname "$0")/../support/cli.sh"

rows=0
while IFS=$'\t' read -r faces name value message; do
    case "$faces" in "#"*|"") continue ;; esac
    case ",$faces," in *,cli,*) ;; *) continue ;; esac
    rows=$((rows + 1))
    impact=0.5,0.5,1 normal=0,0,1 impulse=100
    args=()
    case "$name" in
        impulse) impulse="$value" ;;
        normal) normal="$value" ;;
        point) impact="$value" ;;
        cells) args+=(--cells "$value") ;;
        seed) args+=(--seed "$value") ;;
        depth) args+=(--depth "$value" --format gltf) ;;
        "cells x depth") args+=(--cells "${value%,*}" --depth "${value#*,}" --format gltf) ;;
        roughness) args+=(--roughness "$value") ;;
        hurst) args+=(--roughness 0.1 --hurst "$value") ;;
        feature_size) args+=(--roughness 0.1 --feature-size "$value") ;;
        *) fail "no CLI case for $name" ;;
    esac
    args+=(--impact "$impact" --normal "$normal" --impulse "$impulse")
    out="$tmp/out$rows"
    set +e
    "$RUBBLE" fracture "$cube" "${args[@]}" -o "$out" --json >"$tmp/json" 2>"$tmp/err"
    c=$?
    set -e
    if [ "$message" = ok ]; then
        [ "$c" -eq 0 ] || fail "$name $value: exit $c, expected 0: $(cat "$tmp/err")"
        continue
    fi
    [ "$c" -eq 2 ] || fail "$name $value: exit $c, expected 2"
    grep -qF -- "$message" "$tmp/err" || fail "$name $value: stderr '$(cat "$tmp/err")' lacks '$message'"
    python3 - "$tmp/json" "$message" <<'PY' || fail "$name $value: JSON '$(cat "$tmp/json")' lacks the message"
import json, sys
d = json.load(open(sys.argv[1]))
assert set(d) == {"error"} and sys.argv[2] in d["error"], d
PY
    [ ! -e "$out" ] || fail "$name $value: wrote $out"
done <"$root/tests/data/parameter_cases.tsv"
[ "$rows" -ge 20 ] || fail "only $rows CLI rows in the table"
