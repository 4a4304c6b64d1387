#pragma once
/// \file FractureRequest.hpp
/// One fracture as a value, and the one entry point that carries it out; Fracture.hpp's four overloads are
/// shorthands for it.

#include <cstdint>
#include <optional>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble {

/// One fracture: the mesh, lent or handed over; where it is cut, at an impact from a seed or by given cells;
/// how; and what is known of the mesh. Exactly one of mesh and consumed is set; the pointers are used during
/// the call only.
struct RUBBLE_API FractureRequest {
    /// The mesh lent: left as it is (where it would be cut in place, a copy is).
    const Mesh* mesh = nullptr;
    /// What is known of *mesh (analyzeMesh, Piece::facts), or null.
    const MeshFacts* known = nullptr;
    /// Or the mesh handed over: cut in place when consumedFacts holds its topology and params.backend is Fast
    /// (docs/megamesh.md); left valid but unspecified.
    Mesh* consumed = nullptr;
    /// What is known of *consumed, or null; left valid but unspecified.
    MeshFacts* consumedFacts = nullptr;
    /// The hit: cells are drawn around it from seed.
    Impact impact;
    /// Of the cells, and mixed into params.roughness.seed.
    std::uint64_t seed = 0;
    /// Or the cells to cut by: then impact and seed are unused.
    std::optional<std::vector<ConvexPolytope>> cells;
    /// How it is cut.
    FractureParams params;
};

/// Carries out a request, deciding once whether the mesh is cut in place: as fracture and fractureWithCells
/// (Fracture.hpp) describe. InvalidInput naming the field when the request sets both or neither of mesh and
/// consumed, or facts for the one it does not set.
RUBBLE_API Result<FractureResult> fracture(FractureRequest request);

} // namespace rubble
