// Constrained Delaunay triangulation of planar regions (see PlanarTriangulation.hpp).

#include "geometry/PlanarTriangulation.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace rubble::detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::uint32_t, K>;
using Fbi = CGAL::Triangulation_face_base_with_info_2<int, K>;
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbi>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;

std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
}

} // namespace

void planeBasis(const Vec3& n, Vec3& u, Vec3& v) {
    u = normalized(std::abs(n.x) < 0.6 ? cross(Vec3{1, 0, 0}, n) : cross(Vec3{0, 1, 0}, n));
    v = cross(n, u);
}

const char* triangulatePlanarRegion(const std::vector<RegionEdge>& edges, const Vec3& normal,
                                    const std::function<Vec3(std::uint32_t)>& position,
                                    std::vector<std::array<std::uint32_t, 3>>& out) {
    Vec3 u, v;
    planeBasis(normalized(normal), u, v);
    CDT cdt;
    std::unordered_map<std::uint32_t, CDT::Vertex_handle> handle;
    const char* failure = nullptr;
    auto vertex = [&](std::uint32_t id) {
        auto it = handle.find(id);
        if (it != handle.end())
            return it->second;
        const Vec3 p = position(id);
        const std::size_t before = cdt.number_of_vertices();
        CDT::Vertex_handle h = cdt.insert(K::Point_2(dot(p, u), dot(p, v)));
        if (cdt.number_of_vertices() != before + 1)
            failure = "coincident points in a planar region";
        h->info() = id;
        handle.emplace(id, h);
        return h;
    };
    std::unordered_map<std::uint64_t, unsigned> flags;
    for (const RegionEdge& e : edges) {
        const CDT::Vertex_handle a = vertex(e.a), b = vertex(e.b);
        if (failure)
            return failure;
        cdt.insert_constraint(a, b);
        flags[pairKey(e.a, e.b)] ^= e.toggle;
    }
    if (cdt.number_of_vertices() != handle.size())
        return "edges of a planar region cross";

    for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
        f->info() = -1;
    std::vector<CDT::Face_handle> queue;
    for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
        if (cdt.is_infinite(f)) {
            f->info() = 0;
            queue.push_back(f);
        }
    while (!queue.empty()) {
        const CDT::Face_handle f = queue.back();
        queue.pop_back();
        for (int i = 0; i < 3; ++i) {
            const CDT::Face_handle n = f->neighbor(i);
            const CDT::Vertex_handle a = f->vertex(CDT::cw(i)), b = f->vertex(CDT::ccw(i));
            unsigned toggle = 0;
            if (!cdt.is_infinite(a) && !cdt.is_infinite(b)) {
                auto it = flags.find(pairKey(a->info(), b->info()));
                if (it != flags.end())
                    toggle = it->second;
            }
            const int state = f->info() ^ static_cast<int>(toggle);
            if (n->info() < 0) {
                n->info() = state;
                queue.push_back(n);
            } else if (n->info() != state) {
                return "the boundary of a planar region is not closed";
            }
        }
    }
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        if (f->info() != 1)
            continue;
        if (CGAL::orientation(f->vertex(0)->point(), f->vertex(1)->point(), f->vertex(2)->point()) !=
            CGAL::LEFT_TURN)
            return "flat triangle in a planar region";
        out.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
    }
    return nullptr;
}

} // namespace rubble::detail
