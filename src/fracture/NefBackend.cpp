// Boolean backend on CGAL Nef_polyhedron_3 (the thesis's method), kept as a reference for benchmarks and
// cross-checks. Nef needs exact constructions (Epeck). It merges coplanar faces, so per-face sources are
// lost: output faces are matched geometrically to the input (assembleMesh), and attributes of a merged face
// are interpolated from one input triangle of its plane.

#include <algorithm>
#include <map>
#include <tuple>

// GCC's -Wmaybe-uninitialized fires inside CGAL's templates instantiated here (false positives).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Nef_polyhedron_3.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/convert_nef_polyhedron_to_polygon_mesh.h>

#include "BooleanBackends.hpp"

namespace rubble::detail {

namespace {

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using SM = CGAL::Surface_mesh<K::Point_3>;
using Nef = CGAL::Nef_polyhedron_3<K>;

/// A deterministic double for a lazy exact number: the approximation when it is a single double (e.g. an
/// input coordinate), else the rounded exact value. CGAL::to_double of the interval is not deterministic:
/// it depends on whether earlier predicates happened to refine the interval.
double toDouble(const K::FT& x) {
    const auto& a = x.approx();
    if (a.inf() == a.sup())
        return a.inf();
    return CGAL::to_double(x.exact());
}

struct Failure {
    std::string why;
};

SM meshToSm(const Mesh& m) {
    SM sm;
    for (const Vec3& p : m.positions)
        sm.add_vertex(K::Point_3(p.x, p.y, p.z));
    for (const Triangle& t : m.triangles)
        if (sm.add_face(SM::Vertex_index(t[0]), SM::Vertex_index(t[1]), SM::Vertex_index(t[2])) ==
            SM::null_face())
            throw Failure{"the mesh is not a manifold surface"};
    return sm;
}

SM cellToSm(const ConvexPolytope& cell) {
    SM sm;
    std::map<std::tuple<double, double, double>, SM::Vertex_index> index;
    for (const PolytopeFace& face : cell.faces()) {
        std::vector<SM::Vertex_index> loop;
        for (const Vec3& p : face.corners) {
            auto [it, inserted] = index.emplace(std::make_tuple(p.x, p.y, p.z), SM::Vertex_index());
            if (inserted)
                it->second = sm.add_vertex(K::Point_3(p.x, p.y, p.z));
            if (loop.empty() || loop.back() != it->second)
                loop.push_back(it->second);
        }
        while (loop.size() > 1 && loop.front() == loop.back())
            loop.pop_back();
        if (loop.size() < 3)
            continue;
        // Triangles: the double corners of a face need not be exactly coplanar, and Nef needs planar faces.
        for (std::size_t i = 1; i + 1 < loop.size(); ++i)
            if (sm.add_face(loop[0], loop[i], loop[i + 1]) == SM::null_face())
                throw Failure{"a cell is not a closed convex polytope"};
    }
    if (!CGAL::is_closed(sm))
        throw Failure{"a cell is not closed"};
    return sm;
}

Mesh nefToMesh(const Nef& nef, const Mesh& input) {
    if (nef.is_empty())
        return {};
    SM sm;
    CGAL::convert_nef_polyhedron_to_polygon_mesh(nef, sm, true);
    std::vector<Vec3> positions;
    std::vector<std::uint32_t> local(sm.num_vertices(), 0xFFFFFFFFu);
    std::vector<Triangle> tris;
    for (SM::Face_index f : sm.faces()) {
        Triangle tri{};
        int c = 0;
        for (SM::Vertex_index v : CGAL::vertices_around_face(sm.halfedge(f), sm)) {
            if (c == 3)
                throw Failure{"a non-triangular face in the output"};
            const auto i = static_cast<std::size_t>(v);
            if (local[i] == 0xFFFFFFFFu) {
                local[i] = static_cast<std::uint32_t>(positions.size());
                const K::Point_3& p = sm.point(v);
                positions.push_back({toDouble(p.x()), toDouble(p.y()), toDouble(p.z())});
            }
            tri[static_cast<std::size_t>(c++)] = local[i];
        }
        if (c != 3)
            throw Failure{"a degenerate face in the output"};
        tris.push_back(tri);
    }
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
