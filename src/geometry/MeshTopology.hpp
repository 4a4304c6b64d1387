#pragma once
// Private to the core: the adjacency of a closed mesh (each triangle's neighbour across each edge), kept by a
// piece of a large mesh from one fracture to the next so that the next cut is checked and split only where it
// touches (docs/megamesh.md). MeshFacts holds it as a HeldTopology (rubble/fracture/Fracture.hpp).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "rubble/geometry/Mesh.hpp"

namespace rubble {

/// Meshes with more triangles than this carry a MeshTopology in their facts (analyzeMesh, fracture's pieces);
/// smaller ones are fractured by copying.
inline constexpr std::size_t kTopologyAboveTriangles = 20000;

/// The half-edge twins of a closed, consistently oriented mesh that is one edge-connected shell.
/// Half-edge 3t + c runs from triangles[t][c] to triangles[t][(c + 1) % 3]; twin[3t + c] is the half-edge
/// that runs back along it (12 bytes per triangle). Empty means unknown.
struct MeshTopology {
    std::vector<std::uint32_t> twin; ///< per half-edge, its opposite half-edge
    /// True when this is non-empty and sized for mesh (it must also belong to mesh, as MeshFacts do).
    bool fits(const Mesh& mesh) const { return !twin.empty() && twin.size() == 3 * mesh.triangles.size(); }
    bool operator==(const MeshTopology&) const = default;
};

/// The topology of mesh when it is closed, consistently oriented and one edge-connected shell (every
/// directed edge once, its reverse once); nullopt otherwise. Linear in the mesh.
std::optional<MeshTopology> buildTopology(const Mesh& mesh);

} // namespace rubble
