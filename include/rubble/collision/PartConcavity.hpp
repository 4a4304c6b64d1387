#pragma once
/// \file PartConcavity.hpp
/// How far a set of convex parts is from the surface it stands for (docs/collision.md).

#include <cstddef>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble {

struct FractureResult;

/// The one-sided Hausdorff distance from a closed mesh's surface to the boundary of its convex parts, as a
/// fraction of the mesh's bounding-box diagonal: over samples of the surface (deterministic, area-weighted),
/// the largest depth of a sample inside a part (a pocket the part covers) or distance outside every part (a
/// hole in the cover). 0 for a convex mesh and its hull; a crater covered by a part counts its depth.
RUBBLE_API double partConcavity(const Mesh& mesh, const std::vector<ConvexPolytope>& parts,
                                std::size_t samples = 4096);

/// partConcavity of every piece of a fracture (rubble/fracture/Fracture.hpp) with parts[i], one part list per
/// piece as updateDecomposition returns them; -1 for a piece without parts.
RUBBLE_API std::vector<double> pieceConcavity(const FractureResult& result,
                                              const std::vector<std::vector<ConvexPolytope>>& parts,
                                              std::size_t samples = 4096);

/// Stores pieceConcavity(result, parts, samples) in result.concavity and returns it. Opt-in: it adds 16-40 %
/// to an impact's pieces with their parts (docs/collision.md).
RUBBLE_API const std::vector<double>& recordConcavity(FractureResult& result,
                                                      const std::vector<std::vector<ConvexPolytope>>& parts,
                                                      std::size_t samples = 4096);

} // namespace rubble
