#!/usr/bin/env bash
# Rubble as a package, tested from outside (CTest label `package`):
#   run.sh install   BUILD WORK            cmake --install BUILD into the fresh prefix WORK/prefix; checks its layout
#   run.sh cmake     BUILD WORK CXX        configures and builds tests/package against WORK/prefix (find_package)
#   run.sh pkgconfig BUILD WORK CXX        c++ pkgconfig_hello.cpp $(pkg-config --cflags --libs rubble), runs it
#   run.sh python    BUILD WORK PY SITE    imports the installed module (PY, WORK/prefix/SITE) and fractures a box
# The consumers see only the prefix: the packages the config must not need (CGAL, Eigen, ...) are disabled.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
step=$1 build=$2 work=$3
prefix=$work/prefix
# The same compiler cache as the main build (tests/package lies in the source tree; see CMakeLists.txt).
launcher=()
if command -v ccache >/dev/null; then
    export CCACHE_BASEDIR=$(cd "$here/../.." && pwd) CCACHE_NOHASHDIR=1
    launcher=(ccache)
fi

fail() {
    echo "package test: $*" >&2
    exit 1
}

case "$step" in
install)
    rm -rf "$prefix"
    cmake --install "$build" --prefix "$prefix" --strip >"$work.install.log" || { cat "$work.install.log"; exit 1; }
    libdir=$(cd "$prefix" && ls -d lib*/cmake/Rubble | sed 's#/cmake/Rubble##')
    for f in "$libdir"/cmake/Rubble/RubbleConfig.cmake "$libdir"/cmake/Rubble/RubbleConfigVersion.cmake \
        "$libdir"/cmake/Rubble/RubbleTargets.cmake "$libdir"/cmake/Rubble/RubbleBulletTargets.cmake \
        "$libdir"/pkgconfig/rubble.pc "$libdir"/pkgconfig/rubble-bullet.pc "$libdir"/librubble.so \
        "$libdir"/librubble_bullet.so include/rubble/rubble.hpp include/rubble/rubble.h include/rubble/geometry/Mesh.hpp \
        include/rubble/bullet/BulletBinding.hpp bin/rubble; do
        [ -e "$prefix/$f" ] || fail "missing $f in the installed tree"
    done
    # librubble.so needs only the runtime libraries docs/hello.md names (no CGAL, Eigen or Boost at all).
    needed=$(readelf -d "$prefix/$libdir/librubble.so" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
    for lib in $needed; do
        case "$lib" in
        libvoro++.so.* | libqhull_r.so.* | libgmp.so.* | libmpfr.so.* | libassimp.so.* | libcholmod.so.* | \
            libsuitesparseconfig.so.* | libstdc++.so.* | \
            libm.so.* | libgcc_s.so.* | libc.so.* | ld-linux*) ;;
        *) fail "librubble.so needs $lib, which docs/hello.md does not name" ;;
        esac
    done
    # librubble.so and librubble_bullet.so export Rubble's API only: no CGAL, Bullet, Boost or standard-library
    # instance.
    for so in librubble.so librubble_bullet.so; do
        exported=$(nm -D --defined-only "$prefix/$libdir/$so" | awk '{print $3}' | c++filt)
        foreign=$(echo "$exported" | grep -vE '^(rubble::|rubble_|typeinfo for rubble::|typeinfo name for rubble::|vtable for rubble::|non-virtual thunk to rubble::)' || true)
        [ -z "$foreign" ] || fail "$so exports $(echo "$foreign" | wc -l) symbols that are not Rubble's, e.g. $(echo "$foreign" | head -3)"
        echo "$so exports $(echo "$exported" | wc -l) symbols"
    done
    # The install is lean: stripped, and the CLI and the Python module share librubble.so (558 MB before).
    size_mb=$(du -sm "$prefix" | cut -f1)
    [ "$size_mb" -le 50 ] || fail "the installed tree takes $size_mb MB, over 50"
    # The CLI links librubble.so instead of a second copy of the library.
    readelf -d "$prefix/bin/rubble" | grep -q 'NEEDED.*librubble\.so' || fail "bin/rubble does not link librubble.so"
    "$prefix/bin/rubble" --version >/dev/null || fail "the installed bin/rubble does not run"
    # Nothing installed may point back into the source or build tree.
    src=$(cd "$here/../.." && pwd)
    if grep -rl -e "$src" -e "$(cd "$build" && pwd)" "$prefix/$libdir/cmake" "$prefix/$libdir/pkgconfig"; then
        fail "installed package files refer to the source or build tree"
    fi
    echo "installed into $prefix"
    ;;
cmake)
    cxx=$4
    rm -rf "$work/consumer"
    cmake -S "$here" -B "$work/consumer" -G Ninja --no-warn-unused-cli -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$cxx" \
        -DCMAKE_CXX_COMPILER_LAUNCHER="${launcher[*]}" -DCMAKE_PREFIX_PATH="$prefix" \
        -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_DISABLE_FIND_PACKAGE_CGAL=ON \
        -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON \
        -DCMAKE_DISABLE_FIND_PACKAGE_CLI11=ON -DCMAKE_DISABLE_FIND_PACKAGE_GTest=ON \
        -DCMAKE_DISABLE_FIND_PACKAGE_pybind11=ON >"$work/consumer.log" || { cat "$work/consumer.log"; exit 1; }
    cmake --build "$work/consumer" >>"$work/consumer.log" || { cat "$work/consumer.log"; exit 1; }
    "$work/consumer/consumer"
    ;;
pkgconfig)
    cxx=$4
    libdir=$(cd "$prefix" && ls -d lib*/pkgconfig | sed 's#/pkgconfig##')
    export PKG_CONFIG_PATH=$prefix/$libdir/pkgconfig
    # shellcheck disable=SC2046 # the flags are meant to split
    "${launcher[@]}" "$cxx" "$here/pkgconfig_hello.cpp" -o "$work/pkgconfig_hello" $(pkg-config --cflags --libs rubble)
    "$work/pkgconfig_hello"
    pkg-config --exists --print-errors rubble-bullet
    ;;
python)
    python=$4 site=$5
    for f in __init__.py __init__.pyi py.typed; do
        [ -e "$prefix/$site/rubble/$f" ] || fail "missing $site/rubble/$f in the installed tree"
    done
    PYTHONPATH=$prefix/$site PYTHONDONTWRITEBYTECODE=1 "$python" - "$prefix" <<'PY'
import sys

import rubble

prefix = sys.argv[1]
assert rubble.__file__.startswith(prefix), f"imported {rubble.__file__}, not the installed module"
pieces = rubble.fracture(rubble.box((-1, -1, -1), (1, 1, 1), 3), point=(0, 1, 0), impulse=20, seed=3)
volume = sum(p.volume for p in pieces)
assert len(pieces) >= 2 and abs(volume - 8) < 1e-8, (len(pieces), volume)
print(f"python: {len(pieces)} pieces from {rubble.__file__}, volume {volume:.9f} of 8")
PY
    ;;
*)
    fail "unknown step $step"
    ;;
esac
