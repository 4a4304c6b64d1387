#!/usr/bin/env bash
# Installs the Debian 12 packages Rubble needs, and only the missing ones.
# Idempotent: a second run with everything present installs nothing and takes well under a second.
# Works as root and, for other users, through sudo. Usage: scripts/install-deps.sh [core|all]
set -euo pipefail

core=(
    build-essential cmake ninja-build pkg-config ccache clang-format lld
    libcgal-dev libgmp-dev libmpfr-dev libboost-dev libeigen3-dev voro++-dev libqhull-dev libtbb-dev
    libsuitesparse-dev libopenblas0-serial
    libassimp-dev nlohmann-json3-dev libcli11-dev
    libgtest-dev libgmock-dev libbenchmark-dev
    libbullet-dev libenet-dev zlib1g-dev libzstd-dev
    pybind11-dev python3-dev python3-numpy python3-pytest
    libglfw3-dev libimgui-dev libepoxy-dev libstb-dev libegl-dev libgl-dev libgl1-mesa-dri libopenal-dev
    xvfb xauth xdotool gnuplot-nox
    blender
)
extra=(clang libclang-rt-14-dev ffmpeg) # ffmpeg: scripts/readme-animation.sh

want=("${core[@]}")
if [ "${1:-core}" = all ]; then want+=("${extra[@]}"); fi

missing=()
for p in "${want[@]}"; do
    status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
    case "$status" in
        *"install ok installed"*) ;;
        *) missing+=("$p") ;;
    esac
done

if [ ${#missing[@]} -eq 0 ]; then
    exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then
        sudo_cmd=(sudo)
    else
        echo "install-deps: need root or sudo to install: ${missing[*]}" >&2
        exit 1
    fi
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
