// Built with nothing but `c++ pkgconfig_hello.cpp $(pkg-config --cflags --libs rubble)` against an installed
// Rubble (tests/package/run.sh): the C++ API and the C API from one file.
#include <cmath>
#include <cstdio>

#include "rubble/rubble.h"
#include "rubble/rubble.hpp"

int main() {
    const rubble::Mesh cube = rubble::makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 3);
    rubble::Impact impact;
    impact.point = {0, 1, 0};
    impact.impulse = 20;
    const rubble::Result<rubble::FractureResult> broken = rubble::fracture(cube, impact, {}, 3);
    if (!broken) {
        std::fprintf(stderr, "%s\n", broken.error().message.c_str());
        return 1;
    }
    double volume = broken->droppedVolume;
    for (const rubble::Piece& piece : broken->pieces)
        volume += piece.mass.volume;
    std::printf("pkg-config: %zu pieces, volume %.9f of 8, C API version %u\n", broken->pieces.size(), volume,
                rubble_api_version());
    return broken->pieces.size() >= 2 && std::abs(volume - 8) < 1e-8 &&
                   rubble_api_version() == RUBBLE_C_API_VERSION
               ? 0
               : 1;
}
