#pragma once
// Private to rubble_fracture: the boolean backends and the helpers they share.

#include <cstdint>
#include <memory>
#include <vector>

#include "BooleanBackend.hpp"
#include "ConvexCellClipper.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// CGAL Polygon_mesh_processing corefinement backend (exact constructions; see CorefineBackend.cpp).
std::unique_ptr<BooleanBackend> makeCorefineBackend();
/// CGAL Nef_polyhedron_3 backend (the thesis's method).
std::unique_ptr<BooleanBackend> makeNefBackend();
/// A split whose remainder is an edit of the input (RemainderEdit), for meshes edited in place.
struct SplitEdit {
    RemainderEdit remainder;             ///< mesh − ∪ cells as an edit of mesh
    std::vector<Mesh> inside;            ///< inside[i] = mesh ∩ cells[i] (may be empty)
    std::vector<std::size_t> insideKept; ///< per cell: inside[i]'s first triangles are input triangles kept
                                         ///< whole, the rest new (all new when unknown: 0)
    VolumeIntegrals remainderIntegrals;  ///< of the remainder, by difference
};

/// A backend that can also give the remainder as an edit of the input.
class EditingBackend : public BooleanBackend {
public:
    /// As split, with the remainder as an edit of mesh (whose integrals the backend was given; bounds are
    /// mesh's). Errors (declined configurations included) leave the caller to split another way.
    virtual Result<SplitEdit> splitAsEdit(const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                                          const Aabb& bounds) const = 0;
};

/// Convex-cell clipper backend (an EditingBackend when given inputIntegrals); with exactFallback, Corefine
/// makes the splits the clipper declines, else they are errors. With inputIntegrals (the split mesh's, which
/// must outlive the backend), its splits carry the remainder's integrals by difference
/// (SplitResult::remainderIntegrals).
std::unique_ptr<BooleanBackend> makeFastBackend(bool exactFallback = true,
                                                const VolumeIntegrals* inputIntegrals = nullptr);

/// Source of an output triangle: >= 0 an input triangle, kCutFace a cell face, kUnknownSource not known
/// (found geometrically by assembleMesh).
inline constexpr std::int64_t kCutFace = -1;
/// See kCutFace.
inline constexpr std::int64_t kUnknownSource = -2;

/// Builds an output mesh from positions, triangles and per-triangle sources: triangles from the input keep
/// its material and get its per-corner normals/uvs interpolated barycentrically; cut faces get
/// kInteriorMaterial, their geometric normal (when the input has normals) and zero uvs (filled later by
/// the fracture pipeline). Unknown sources are resolved geometrically (nearest input triangle when the
/// triangle lies on the input surface, a cut face otherwise). Always produces uvs and materials.
Mesh assembleMesh(const Mesh& input, std::vector<Vec3> positions, const std::vector<Triangle>& triangles,
                  std::vector<std::int64_t> sources);

/// Closed, edge-manifold and consistently oriented at Mesh level: every directed edge appears exactly once
/// and its reverse exactly once.
bool isClosedOriented(const Mesh& mesh);

} // namespace rubble::detail
