#pragma once
// Private to rubble_fracture (and its tests): the verification every split passes and the pipeline with an
// explicit backend, so that tests can inject faulty splits.

#include <cstdint>
#include <vector>

#include "BooleanBackend.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// Shell labels of one split output, as labelShells gives them.
struct OutputShells {
    std::vector<std::uint32_t> triangleShell; ///< shell of each triangle
    std::size_t count = 0;                    ///< number of shells
};

/// The verification every split passes before it becomes pieces: each non-empty output valid, closed,
/// consistently oriented with positive volume, and the volumes summing to inputVolume (relative 1e-7).
/// With shells, also the shell labels of the remainder and then of each inside mesh (found in the same pass).
/// otherVolume: of an output checked elsewhere (a remainder edited in place), counted in the sum.
bool splitIsSound(const SplitResult& split, double inputVolume, std::vector<OutputShells>* shells = nullptr,
                  double otherVolume = 0);

/// fractureWithCells with an explicit backend (tests inject faulty ones). A split that fails splitIsSound
/// is redone by Corefine when exactRedo is set (then FractureStats::exactFallback), else it is an error.
/// known: as for fracture (the backend is given the integrals by the caller).
Result<FractureResult> fractureWithBackend(const Mesh& mesh, std::vector<ConvexPolytope> cells,
                                           const FractureParams& params, const BooleanBackend& backend,
                                           bool exactRedo, const MeshFacts& known = {});

/// fractureWithBackend on a mesh whose facts hold its topology, with a backend that edits (EditingBackend;
/// otherwise as fractureWithBackend): the remainder is mesh edited in place, and known.topology with it. An
/// error leaves mesh and known as they were; on success, mesh is consumed.
Result<FractureResult> fractureInPlaceWithBackend(Mesh& mesh, MeshFacts& known,
                                                  std::vector<ConvexPolytope> cells,
                                                  const FractureParams& params, const BooleanBackend& backend,
                                                  bool exactRedo);

} // namespace rubble::detail
