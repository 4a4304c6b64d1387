#pragma once
// A hash of a fracture's pieces, shared by the determinism tests.

#include <cstdint>

#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble::test {

/// A hash of a fracture's pieces' meshes, in order (same seed → same bytes), each hashed by meshHash.
inline std::uint64_t hashPieces(const FractureResult& r, std::uint64_t (*meshHash)(const Mesh&) = nullptr) {
    std::uint64_t h = 1469598103934665603ull;
    for (const Piece& p : r.pieces)
        h = mixSeed(h, meshHash ? meshHash(p.mesh) : p.mesh.hash());
    return h;
}

} // namespace rubble::test
