#pragma once
// Private to rubble_fracture (its tests and rubble-bench): the boolean backends' interface.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rubble/core/Result.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble {

/// Result of splitting a mesh by disjoint convex cells.
struct SplitResult {
    Mesh remainder;             ///< mesh − ∪ cells (may be empty)
    std::vector<Mesh> inside;   ///< inside[i] = mesh ∩ cells[i] (may be empty)
    bool exactFallback = false; ///< a fast backend declined and an exact backend made this split
    /// The remainder's volume integrals when the backend derived them from the input's (Fast, given known
    /// facts): the input's minus the triangles the cut removed plus those it created.
    std::optional<VolumeIntegrals> remainderIntegrals;
};

/// A boolean implementation: splits a closed mesh by disjoint convex cells.
class BooleanBackend {
public:
    virtual ~BooleanBackend() = default;
    /// Short name ("corefine", "nef").
    virtual std::string name() const = 0;
    /// remainder = mesh − ∪cells and inside[i] = mesh ∩ cells[i]. Faces created by cell faces carry
    /// kInteriorMaterial; other faces keep the input's attributes. Errors leave nothing half-done.
    virtual Result<SplitResult> split(const Mesh& mesh, const std::vector<ConvexPolytope>& cells) const = 0;
};

/// The backend of the given kind (Fast without input integrals, with the exact fallback).
std::unique_ptr<BooleanBackend> makeBooleanBackend(BooleanKind kind);

} // namespace rubble
