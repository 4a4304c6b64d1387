#!/usr/bin/env bash
# The core's layers (docs/architecture.md): include/rubble/<layer>/ and src/<layer>/ use only the layers below
# them, public headers use no internal one, and the core knows no physics engine, network library, window
# system or graphics API.
set -euo pipefail
cd "$(dirname "$0")/.."
status=0
pattern='#[[:space:]]*include[[:space:]]*[<"](bullet/|btBulletDynamicsCommon|Bullet|LinearMath/|BulletCollision/|BulletDynamics/|enet/enet|GLFW/|GL/|epoxy/|EGL/|imgui)'
if grep -rnE "$pattern" src include/rubble; then
    echo "check-layering: the core must not include Bullet, ENet, GLFW or OpenGL headers" >&2
    status=1
fi

# What each layer may use besides itself.
declare -A below=(
    [core]=""
    [geometry]="core"
    [structure]="core geometry"
    [fracture]="core geometry"
    [collision]="core geometry fracture"
    [io]="core geometry structure fracture collision"
    [runtime]="core geometry structure fracture collision io"
    [persist]="core geometry structure fracture collision io runtime"
    [capi]="core geometry structure fracture collision io runtime persist"
)
layers="${!below[*]}"

for dir in include/rubble/* src/*; do
    [ -d "$dir" ] || continue
    layer=${dir##*/}
    if [ -z "${below[$layer]+x}" ]; then
        echo "check-layering: $dir is no layer (known: $layers)" >&2
        status=1
        continue
    fi
    allowed=" $layer ${below[$layer]} "
    while IFS=: read -r file line used kind; do
        if [[ "$allowed" != *" $used "* ]]; then
            echo "check-layering: $file:$line: the $layer layer includes $kind from $used" >&2
            status=1
        elif [ "$kind" = internal ] && [[ "$dir" == include/* ]]; then
            echo "check-layering: $file:$line: a public header includes an internal one ($used/)" >&2
            status=1
        fi
    done < <(grep -rnoE '#[[:space:]]*include[[:space:]]*"(rubble/)?[a-z]+/[A-Za-z0-9_]+\.(hpp|h)"' "$dir" |
        sed -nE 's#^([^:]+):([0-9]+):.*"rubble/([a-z]+)/.*#\1:\2:\3:a public header#p; t; s#^([^:]+):([0-9]+):.*"([a-z]+)/.*#\1:\2:\3:internal#p' |
        grep -E ":($(echo "$layers" | tr ' ' '|')):" || true)
done

# Every public header lives in a layer's folder, but the umbrella and the C API.
loose=$(find include/rubble -maxdepth 1 -type f ! -name rubble.hpp ! -name rubble.h)
if [ -n "$loose" ]; then
    echo "check-layering: public headers outside a layer folder: $loose" >&2
    status=1
fi

# The umbrella a game includes compiles alone and stays small: Rubble's own lines it pulls in, transitively.
max_umbrella_lines=2800
cxx=${CXX:-c++}
if ! echo '#include "rubble/rubble.hpp"' | "$cxx" -std=c++20 -fsyntax-only -Iinclude -x c++ -; then
    echo "check-layering: rubble/rubble.hpp does not compile alone" >&2
    status=1
else
    umbrella=$(echo '#include "rubble/rubble.hpp"' | "$cxx" -std=c++20 -Iinclude -MM -x c++ - | sed 's/ *\\$//' |
        tr ' ' '\n' | grep '^include/rubble/' | sort -u)
    # shellcheck disable=SC2086
    lines=$(cat $umbrella | wc -l)
    if [ "$lines" -gt $max_umbrella_lines ]; then
        echo "check-layering: rubble/rubble.hpp pulls in $lines lines of Rubble headers, over $max_umbrella_lines" >&2
        status=1
    fi
fi
[ $status = 0 ] && echo "check-layering: ok (rubble/rubble.hpp: ${lines:-?} lines in $(echo "$umbrella" | wc -l) headers)"
exit $status
