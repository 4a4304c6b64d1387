#!/usr/bin/env bash
# The core (src/, include/rubble/) knows no physics engine, network library, window system or graphics API.
set -euo pipefail
cd "$(dirname "$0")/.."
pattern='#[[:space:]]*include[[:space:]]*[<"](bullet/|btBulletDynamicsCommon|Bullet|LinearMath/|BulletCollision/|BulletDynamics/|enet/enet|GLFW/|GL/|epoxy/|EGL/|imgui)'
if grep -rnE "$pattern" src include/rubble; then
    echo "check-layering: the core must not include Bullet, ENet, GLFW or OpenGL headers (see docs/architecture.md)" >&2
    exit 1
fi
echo "check-layering: ok"
