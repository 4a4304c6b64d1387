#pragma once
// High-poly test meshes of the million-triangle rows: a sphere, a torus and the arch asset
// subdivided, at a given triangle count.

#include <string>
#include <vector>

#include "BenchUtil.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::bench {

/// Every triangle split into n² by an n-way split of its edges (shared edges split alike, so a closed mesh
/// stays closed; the shape does not change).
Mesh subdivideTriangles(const Mesh& mesh, int n);

/// One high-poly mesh: kind "sphere" (a UV sphere: its triangles crowd at the poles), "geosphere" (a
/// subdivided icosahedron: even density), "torus" or "arch" (the repository's arch subdivided) with about
/// `triangles` triangles (exactly for the sphere and torus at 100k, 250k and 1M); the organic kinds "blob" (a
/// body with seven limbs) and "bumpy" (a potato) are the geodesic sphere displaced along its radius.
Mesh megaMesh(const std::string& kind, std::size_t triangles);

/// The mesh with flat per-corner normals and texture coordinates from its positions' x and z.
Mesh withFlatAttributes(Mesh mesh);

/// The kinds of megaMesh.
inline const std::vector<std::string> kMegaKinds = {"sphere", "geosphere", "torus", "arch"};
/// The organic kinds of megaMesh.
inline const std::vector<std::string> kOrganicKinds = {"blob", "bumpy"};

} // namespace rubble::bench

namespace rubble::bench {

/// Options of the million-triangle rows (`--mega` of the impact and decomposition suites).
struct MegaArgs {
    std::vector<std::size_t> sizes{100000, 250000, 1000000}; ///< triangle counts
    std::vector<std::string> kinds = kMegaKinds;             ///< which meshes
    int hits = 20;                                           ///< random hits per mesh
    int chain = 100;    ///< chained hits on the 250k UV and geodesic spheres (0: none)
    std::string out;    ///< results folder
    bool facts = true;  ///< pass each mesh's known facts to fracture (analyzeMesh once, then Piece::facts)
    bool world = false; ///< also run each mesh's hits through a DestructionRuntime on Bullet (the world row)
};

/// `rubble-bench impact --mega`: impact → pieces with convex parts per mesh over random hits, the stages, the
/// clip-only bound, and chained hits; impact_megamesh.csv / .png in args.out.
int runMegaImpact(const MegaArgs& args);

/// The columns of impact_megamesh_world.csv.
std::vector<std::string> worldRowHeader();

/// This process's resident memory (MB).
double residentMb();

/// The world row of one mesh (MegaWorldBench.cpp): hits through a DestructionRuntime on the Bullet binding,
/// beside the kernel's median; false when it cannot run.
bool addWorldRow(const std::string& name, const Mesh& mesh, const std::vector<ConvexPolytope>& parts,
                 const FractureParams& params, const std::vector<Impact>& hits, double kernelMedianMs,
                 Table& table, Table& csv);

/// Writes each mesh of args as OBJ into dir (kind_triangles.obj), for `rubble decompose` and `rubble
/// fracture`.
int writeMegaMeshes(const MegaArgs& args, const std::string& dir);

/// `rubble-bench decomposition --mega`: initial decomposition and update after a hit per mesh;
/// decomposition_megamesh.csv / .png in args.out.
int runMegaDecomposition(const MegaArgs& args);

} // namespace rubble::bench
