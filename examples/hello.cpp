// HelloWorld: see docs/hello.md.
#include <cstdio>

#include "rubble/MassProperties.hpp"
#include "rubble/Mesh.hpp"

int main() {
    const rubble::Mesh cube = rubble::makeBox({-1, -1, -1}, {1, 1, 1});
    const rubble::MassProperties mp = rubble::computeMassProperties(cube);
    std::printf("cube: %zu triangles, volume %.3f\n", cube.triangleCount(), mp.volume);
    return mp.volume > 0 ? 0 : 1;
}
