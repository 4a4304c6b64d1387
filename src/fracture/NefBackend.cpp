// Boolean backend on CGAL Nef_polyhedron_3 (the thesis's method), kept as a reference for benchmarks and
// cross-checks. Nef needs exact constructions (Epeck). It merges coplanar faces, so per-face sources are
// lost: output faces are matched geometrically to the input (assembleMesh), and attributes of a merged face
// are interpolated from one input triangle of its plane.

#include <algorithm>
#include <map>
#include <tuple>

// GCC's -Wmaybe-uninitialized fires inside CGAL's templates instantiated here (false positives).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <CGAL/Nef_polyhedron_3.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/boost/graph/convert_nef_polyhedron_to_polygon_mesh.h>

#include "BooleanBackends.hpp"
#include "ExactMesh.hpp"
#include "rubble/geometry/MeshCheck.hpp"

namespace rubble::detail {

namespace {

using exact::Failure;
using exact::K;
using exact::SM;
using Nef = CGAL::Nef_polyhedron_3<K>;

SM meshToSm(const Mesh& m) {
    SM sm;
    exact::addMesh(m, sm);
    return sm;
}

SM cellToSm(const ConvexPolytope& cell) {
    SM sm;
    exact::addCell(cell, sm);
    return sm;
}

Mesh nefToMesh(const Nef& nef, const Mesh& input) {
    if (nef.is_empty())
        return {};
    SM sm;
    CGAL::convert_nef_polyhedron_to_polygon_mesh(nef, sm, true);
    std::vector<Vec3> positions;
    std::vector<Triangle> tris;
    exact::toTriangles(sm, positions, tris);
    // Nef's output order follows its internal (address-dependent) storage: number the vertices by their
    // coordinates and sort the triangles (each rotated to start at its smallest vertex, keeping its
    // orientation) so that the same input gives the same bytes on every run.
    std::vector<std::uint32_t> order(positions.size());
    for (std::uint32_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        const Vec3 &p = positions[a], &q = positions[b];
        return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z);
    });
    std::vector<std::uint32_t> rank(positions.size());
    std::vector<Vec3> sorted(positions.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) {
        rank[order[i]] = i;
        sorted[i] = positions[order[i]];
    }
    positions = std::move(sorted);
    for (Triangle& t : tris) {
        for (std::uint32_t& v : t)
            v = rank[v];
        while (t[0] > t[1] || t[0] > t[2])
            std::rotate(t.begin(), t.begin() + 1, t.end());
    }
    std::sort(tris.begin(), tris.end());
    std::vector<std::int64_t> sources(tris.size(), kUnknownSource);
    return assembleMesh(input, std::move(positions), tris, std::move(sources));
}

class NefBackend final : public BooleanBackend {
public:
    std::string name() const override { return "nef"; }

    Result<SplitResult> split(const Mesh& mesh, const std::vector<ConvexPolytope>& cells) const override {
        try {
            // Nef polyhedra need a simple solid. On a closed, oriented mesh that intersects itself,
            // CGAL 5.5's binary operations can pair up an odd number of halfedges and write through a bogus
            // handle (a segfault in SNC_external_structure::pair_up_halfedges, found by the fracture fuzzer;
            // the check there is an assertion, off in release builds). Corefinement refuses such input
            // (throw_on_self_intersection); so does this backend.
            if (findSelfIntersections(mesh, 1).pairs > 0)
                throw Failure{"the mesh intersects itself (Nef needs a simple solid)"};
            SM sm = meshToSm(mesh);
            Nef rem(sm);
            if (!rem.is_simple())
                throw Failure{"the mesh is not a simple solid"};
            SplitResult out;
            out.inside.resize(cells.size());
            for (std::size_t i = 0; i < cells.size(); ++i) {
                if (cells[i].empty() || !cells[i].bounds().overlaps(mesh.bounds()))
                    continue;
                SM c = cellToSm(cells[i]);
                const Nef cell(c);
                out.inside[i] = nefToMesh(rem * cell, mesh);
                rem = rem - cell;
            }
            out.remainder = nefToMesh(rem, mesh);
            return out;
        } catch (const Failure& f) {
            return makeError(ErrorCode::GeometryFailure, "nef: " + f.why);
        } catch (const std::exception& e) {
            return makeError(ErrorCode::GeometryFailure, std::string("nef: CGAL failed: ") + e.what());
        } catch (...) {
            return makeError(ErrorCode::GeometryFailure, "nef: CGAL failed");
        }
    }
};

} // namespace

std::unique_ptr<BooleanBackend> makeNefBackend() {
    return std::make_unique<NefBackend>();
}

} // namespace rubble::detail
