#pragma once
// Private to the core: editing a closed mesh in place while keeping its MeshTopology (docs/megamesh.md,
// "The remainder edited in place").

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "geometry/MeshTopology.hpp"
#include "rubble/core/Aabb.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// The corners (3t + k) of some triangles of a mesh bucketed by vertex, in the order the triangles are given.
struct CornersByVertex {
    std::vector<std::uint32_t> offset;  ///< per vertex v, its corners are corners[offset[v], offset[v + 1])
    std::vector<std::uint32_t> corners; ///< corner indices 3t + k
    /// Buckets the corners of triangles tris; false when a corner is out of range.
    bool build(const Mesh& mesh, std::span<const std::uint32_t> tris) {
        return fill(mesh, [&](auto visit) {
            for (std::uint32_t t : tris)
                visit(t);
        });
    }
    /// Buckets the corners of every triangle; false when a corner is out of range.
    bool buildAll(const Mesh& mesh) {
        return fill(mesh, [&](auto visit) {
            for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t)
                visit(t);
        });
    }
    /// The corners at vertex v.
    std::span<const std::uint32_t> at(std::uint32_t v) const {
        return {corners.data() + offset[v], corners.data() + offset[v + 1]};
    }

private:
    /// A counting sort of the corners of the triangles that eachTriangle(visit) visits.
    template <class EachTriangle>
    bool fill(const Mesh& mesh, EachTriangle eachTriangle) {
        const std::size_t nV = mesh.positions.size();
        offset.assign(nV + 1, 0);
        bool inRange = true;
        eachTriangle([&](std::uint32_t t) {
            for (std::uint32_t v : mesh.triangles[t])
                if (v < nV)
                    ++offset[v + 1];
                else
                    inRange = false;
        });
        if (!inRange)
            return false;
        for (std::size_t v = 0; v < nV; ++v)
            offset[v + 1] += offset[v];
        corners.assign(offset[nV], 0);
        std::vector<std::uint32_t> cursor(offset.begin(), offset.end() - 1);
        eachTriangle([&](std::uint32_t t) {
            for (std::uint32_t k = 0; k < 3; ++k)
                corners[cursor[mesh.triangles[t][k]]++] = 3 * t + k;
        });
        return true;
    }
};

/// Triangles with their attributes, laid out as in Mesh (normals only when the mesh has them).
struct TriangleBatch {
    std::vector<Triangle> triangles;
    std::vector<Vec3f> normals;           ///< 3 per triangle, or empty
    std::vector<Vec2f> uvs;               ///< 3 per triangle
    std::vector<std::uint32_t> materials; ///< 1 per triangle
};

/// Replaces the triangles in slots `removed` (sorted, distinct) of a closed mesh with topology by `added`,
/// whose corners index mesh.positions followed by newPositions, when the result is closed and consistently
/// oriented by the local conditions of docs/megamesh.md (checked on the removed and added triangles only).
/// Added triangles take the removed slots in order, then are appended; surplus slots are filled with the
/// last triangles. Returns the added triangles' slots, or nullopt with mesh and topology untouched. The
/// mesh must have uvs and materials (and normals exactly when added has them). Slots in *follow (none of
/// them removed) are renamed when their triangle moves.
std::optional<std::vector<std::uint32_t>> replaceTriangles(Mesh& mesh, MeshTopology& topology,
                                                           std::span<const std::uint32_t> removed,
                                                           std::span<const Vec3> newPositions,
                                                           TriangleBatch&& added,
                                                           std::vector<std::uint32_t>* follow = nullptr);

/// After replaceTriangles on a mesh that was one shell, with `removed` non-empty: true when a walk from the
/// added triangles through those whose bounds meet `near` (and the added ones) reaches every added
/// triangle, which proves that the mesh is still one shell (docs/megamesh.md). False means unknown.
bool stillOneShell(const Mesh& mesh, const MeshTopology& topology, std::span<const std::uint32_t> addedSlots,
                   const Aabb& near);

/// After replaceTriangles on a mesh that was one shell, with `removed` non-empty: the remainder's shells
/// found by walks racing from the added triangles in lockstep (docs/megamesh.md, "Islands by racing walks").
/// Returns the triangles (ascending) of every shell but one, the one whose walk was still running (or the
/// largest); empty when the mesh is one shell. Costs about the walks' count times the second-largest shell.
std::vector<std::vector<std::uint32_t>> racingIslands(const MeshTopology& topology,
                                                      std::span<const std::uint32_t> addedSlots);

/// Moves the closed shells made of `slots` (ascending) out of mesh into their own mesh (vertices numbered
/// in order of first use, attributes carried); mesh keeps its topology, and *follow its renamed slots.
std::optional<Mesh> takeShells(Mesh& mesh, MeshTopology& topology, std::span<const std::uint32_t> slots,
                               std::vector<std::uint32_t>* follow);

/// The seeds and every triangle that shares a corner with one (the stars of their corners), ascending.
std::vector<std::uint32_t> trianglesAround(const Mesh& mesh, const MeshTopology& topology,
                                           std::span<const std::uint32_t> seeds);

/// Removes unreferenced vertices when they are more than a quarter of the vertices a closed mesh of this
/// many triangles references (about half its triangle count); the topology stays valid.
void compactVerticesIfSparse(Mesh& mesh);

} // namespace rubble::detail
