// The exact boolean backend: CGAL corefinement on the Epeck kernel (why: docs/architecture.md, "The exact
// backend").

#include <array>
#include <map>
#include <memory>
#include <optional>

// GCC's -Wmaybe-uninitialized fires inside CGAL's templates instantiated here (false positives).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <CGAL/Polygon_mesh_processing/corefinement.h>

#include "BooleanBackends.hpp"
#include "ExactMesh.hpp"
#include "rubble/geometry/MeshCheck.hpp"

namespace rubble::detail {

namespace {

using exact::Failure;
using exact::K;
using exact::SM;
using exact::toDouble;
namespace PMP = CGAL::Polygon_mesh_processing;

/// Per-face source ids for every mesh the visitor sees (by address; meshes live in unique_ptrs).
struct SourceTable {
    std::map<const SM*, std::vector<std::int64_t>> of;
    std::int64_t current = kUnknownSource;

    std::int64_t get(const SM& tm, SM::Face_index f) {
        auto& v = of[&tm];
        const auto i = static_cast<std::size_t>(f);
        return i < v.size() ? v[i] : kUnknownSource;
    }
    void set(const SM& tm, SM::Face_index f, std::int64_t s) {
        auto& v = of[&tm];
        const auto i = static_cast<std::size_t>(f);
        if (i >= v.size())
            v.resize(i + 1, kUnknownSource);
        v[i] = s;
    }
};

struct SourceVisitor : PMP::Corefinement::Default_visitor<SM> {
    SourceTable* table = nullptr;
    void before_subface_creations(SM::Face_index f, SM& tm) { table->current = table->get(tm, f); }
    void after_subface_created(SM::Face_index f, SM& tm) { table->set(tm, f, table->current); }
    void after_face_copy(SM::Face_index from, const SM& src, SM::Face_index to, SM& dst) {
        table->set(dst, to, table->get(src, from));
    }
};

std::unique_ptr<SM> meshToSm(const Mesh& m, SourceTable& table) {
    auto sm = std::make_unique<SM>();
    table.of[sm.get()].resize(m.triangles.size(), kUnknownSource);
    exact::addMesh(m, *sm,
                   [&](std::size_t t, SM::Face_index f) { table.set(*sm, f, static_cast<std::int64_t>(t)); });
    return sm;
}

std::unique_ptr<SM> cellToSm(const ConvexPolytope& cell, SourceTable& table) {
    auto sm = std::make_unique<SM>();
    exact::addCell(cell, *sm, [&](SM::Face_index f) { table.set(*sm, f, kCutFace); });
    return sm;
}

Mesh smToMesh(const SM& sm, SourceTable& table, const Mesh& input) {
    std::vector<Vec3> positions;
    std::vector<Triangle> tris;
    std::vector<std::int64_t> sources;
    sources.reserve(sm.number_of_faces());
    exact::toTriangles(sm, positions, tris, [&](SM::Face_index f) { sources.push_back(table.get(sm, f)); });
    return assembleMesh(input, std::move(positions), tris, std::move(sources));
}

Aabb smBounds(const SM& sm) {
    Aabb b;
    for (SM::Vertex_index v : sm.vertices()) {
        const auto bb = sm.point(v).bbox();
        b.extend(Vec3{bb.xmin(), bb.ymin(), bb.zmin()});
        b.extend(Vec3{bb.xmax(), bb.ymax(), bb.zmax()});
    }
    return b;
}

/// Named parameters for the mesh side of a corefinement. A self-intersecting (e.g. self-touching) input
/// violates corefinement's precondition and made CGAL 5.5 segfault in its constrained triangulation (found by
/// FractureFuzz: two boxes sharing a face); CGAL then checks the triangles near the intersection and throws
/// instead.
auto meshParameters(SourceVisitor& visitor) {
    return PMP::parameters::visitor(visitor).throw_on_self_intersection(true);
}

/// What CGAL's "self-intersection detected" means here: the input intersects itself, or (the cells being
/// convex) an intermediate result of the cut does.
std::string selfIntersectionMessage(const Mesh& mesh) {
    const SelfIntersectionResult s = findSelfIntersections(mesh, 1);
    if (s.pairs > 0)
        return "corefine: the mesh intersects itself (triangles " + std::to_string(s.examples[0].first) +
               " and " + std::to_string(s.examples[0].second) + "); repair it first";
    return "corefine: CGAL found intersecting triangles in an intermediate result of the cut (a degenerate "
           "contact between a cell and the mesh; the mesh itself does not intersect itself)";
}

class CorefineBackend final : public BooleanBackend {
public:
    std::string name() const override { return "corefine"; }

    Result<SplitResult> split(const Mesh& mesh, const std::vector<ConvexPolytope>& cells) const override {
        try {
            return run(mesh, cells);
        } catch (const Failure& f) {
            return makeError(ErrorCode::GeometryFailure, "corefine: " + f.why);
        } catch (const PMP::Corefinement::Self_intersection_exception&) {
            return makeError(ErrorCode::GeometryFailure, selfIntersectionMessage(mesh));
        } catch (const std::exception& e) {
            return makeError(ErrorCode::GeometryFailure, std::string("corefine: CGAL failed: ") + e.what());
        } catch (...) {
            return makeError(ErrorCode::GeometryFailure, "corefine: CGAL failed");
        }
    }

private:
    static SplitResult run(const Mesh& mesh, const std::vector<ConvexPolytope>& cells) {
        std::vector<std::size_t> touching;
        const Aabb box = mesh.bounds();
        for (std::size_t i = 0; i < cells.size(); ++i)
            if (!cells[i].empty() && cells[i].bounds().overlaps(box))
                touching.push_back(i);
        if (touching.size() > 1) {
            try {
                if (auto r = runIndependent(mesh, cells, touching))
                    return std::move(*r);
            } catch (const PMP::Corefinement::Self_intersection_exception&) {
                // The union of many cells can hold fan triangles that fold by rounding where a cell face
                // has a near-collinear corner (found by the shatter sweep: 135 cells on building.obj).
            }
            // Cutting adjacent cells one after the other makes corefinement meet exactly coincident faces,
            // where CGAL 5.5 can crash (a segfault in Face_graph_output_builder, found by the
            // chained-fracture stress test on a valid 110-triangle piece and 5 shatter cells). Nef polyhedra
            // handle that case, and the one above.
            auto nef = makeNefBackend()->split(mesh, cells);
            if (!nef)
                throw Failure{nef.error().message};
            return std::move(*nef);
        }
        return runSequential(mesh, cells);
    }

    /// Several cells: inside[i] = mesh ∩ cell_i each from the input, remainder = mesh − U with U the union
    /// of the cells as one closed surface (faces shared by two welded cells cancel). Cutting the cells one
    /// after the other from the remainder would make CGAL meet faces that coincide exactly (the shared
    /// faces), where its box intersection breaks ties by memory address: the output would not be
    /// bit-identical from run to run. Returns nothing when the union is not a manifold surface.
    static std::optional<SplitResult> runIndependent(const Mesh& mesh,
                                                     const std::vector<ConvexPolytope>& cells,
                                                     const std::vector<std::size_t>& touching) {
        SourceTable table;
        SplitResult out;
        out.inside.resize(cells.size());
        std::vector<std::unique_ptr<SM>> insides(cells.size());
        // The union's triangles: every cell's canonical fan triangles, minus pairs of opposite ones.
        std::map<std::tuple<double, double, double>, std::uint32_t> index;
        std::vector<Vec3> points;
        std::map<std::array<std::uint32_t, 3>, int> tris;
        auto canonical = [](std::array<std::uint32_t, 3> t) {
            std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
            return t;
        };
        for (std::size_t i : touching) {
            std::unique_ptr<SM> cell = cellToSm(cells[i], table);
            std::vector<std::uint32_t> id(cell->num_vertices());
            for (SM::Vertex_index v : cell->vertices()) {
                const K::Point_3& p = cell->point(v);
                const Vec3 q{toDouble(p.x()), toDouble(p.y()), toDouble(p.z())};
                auto [it, inserted] =
                    index.emplace(std::make_tuple(q.x, q.y, q.z), static_cast<std::uint32_t>(points.size()));
                if (inserted)
                    points.push_back(q);
                id[static_cast<std::size_t>(v)] = it->second;
            }
            for (SM::Face_index f : cell->faces()) {
                std::array<std::uint32_t, 3> t{};
                int c = 0;
                for (SM::Vertex_index v : CGAL::vertices_around_face(cell->halfedge(f), *cell))
                    t[static_cast<std::size_t>(c++ % 3)] = id[static_cast<std::size_t>(v)];
                const auto key = canonical(t);
                const auto twin = canonical({t[0], t[2], t[1]});
                if (auto it = tris.find(twin); it != tris.end() && it->second > 0)
                    --it->second;
                else
                    ++tris[key];
            }
            std::unique_ptr<SM> m = meshToSm(mesh, table);
            auto inter = std::make_unique<SM>();
            std::array<boost::optional<SM*>, 4> outputs;
            outputs[PMP::Corefinement::INTERSECTION] = inter.get();
            SourceVisitor visitor;
            visitor.table = &table;
            const std::array<bool, 4> ok =
                PMP::corefine_and_compute_boolean_operations(*m, *cell, outputs, meshParameters(visitor));
            if (!ok[PMP::Corefinement::INTERSECTION])
                throw Failure{"the result of cell " + std::to_string(i) + " would not be a manifold surface"};
            table.of.erase(m.get());
            table.of.erase(cell.get());
            insides[i] = std::move(inter);
        }
        auto uni = std::make_unique<SM>();
        for (const Vec3& p : points)
            uni->add_vertex(K::Point_3(p.x, p.y, p.z));
        for (const auto& [t, count] : tris) {
            if (count <= 0)
                continue;
            if (count > 1)
                return std::nullopt;
            const SM::Face_index f =
                uni->add_face(SM::Vertex_index(t[0]), SM::Vertex_index(t[1]), SM::Vertex_index(t[2]));
            if (f == SM::null_face())
                return std::nullopt;
            table.set(*uni, f, kCutFace);
        }
        if (!CGAL::is_closed(*uni))
            return std::nullopt;
        std::unique_ptr<SM> m = meshToSm(mesh, table);
        auto diff = std::make_unique<SM>();
        std::array<boost::optional<SM*>, 4> outputs;
        outputs[PMP::Corefinement::TM1_MINUS_TM2] = diff.get();
        SourceVisitor visitor;
        visitor.table = &table;
        const std::array<bool, 4> ok =
            PMP::corefine_and_compute_boolean_operations(*m, *uni, outputs, meshParameters(visitor));
        if (!ok[PMP::Corefinement::TM1_MINUS_TM2])
            return std::nullopt;
        for (std::size_t i = 0; i < cells.size(); ++i)
            if (insides[i])
                out.inside[i] = smToMesh(*insides[i], table, mesh);
        out.remainder = smToMesh(*diff, table, mesh);
        return out;
    }

    static SplitResult runSequential(const Mesh& mesh, const std::vector<ConvexPolytope>& cells) {
        SourceTable table;
        std::unique_ptr<SM> rem = meshToSm(mesh, table);
        SplitResult out;
        out.inside.resize(cells.size());
        std::vector<std::unique_ptr<SM>> insides(cells.size());
        Aabb remBox = mesh.bounds();
        for (std::size_t i = 0; i < cells.size(); ++i) {
            if (cells[i].empty() || !cells[i].bounds().overlaps(remBox))
                continue;
            std::unique_ptr<SM> cell = cellToSm(cells[i], table);
            auto inter = std::make_unique<SM>();
            auto diff = std::make_unique<SM>();
            std::array<boost::optional<SM*>, 4> outputs;
            outputs[PMP::Corefinement::INTERSECTION] = inter.get();
            outputs[PMP::Corefinement::TM1_MINUS_TM2] = diff.get();
            SourceVisitor visitor;
            visitor.table = &table;
            const std::array<bool, 4> ok =
                PMP::corefine_and_compute_boolean_operations(*rem, *cell, outputs, meshParameters(visitor));
            if (!ok[PMP::Corefinement::INTERSECTION] || !ok[PMP::Corefinement::TM1_MINUS_TM2])
                throw Failure{"the result of cell " + std::to_string(i) + " would not be a manifold surface"};
            table.of.erase(rem.get());
            table.of.erase(cell.get());
            rem = std::move(diff);
            insides[i] = std::move(inter);
            if (rem->is_empty())
                break;
            remBox = smBounds(*rem);
        }
        for (std::size_t i = 0; i < cells.size(); ++i)
            if (insides[i])
                out.inside[i] = smToMesh(*insides[i], table, mesh);
        out.remainder = smToMesh(*rem, table, mesh);
        return out;
    }
};

} // namespace

std::unique_ptr<BooleanBackend> makeCorefineBackend() {
    return std::make_unique<CorefineBackend>();
}

} // namespace rubble::detail
