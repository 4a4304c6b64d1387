// Conversions shared by the exact CGAL backends (see ExactMesh.hpp).

#include <algorithm>
#include <map>
#include <tuple>

// GCC's -Wmaybe-uninitialized fires inside CGAL's templates instantiated here (false positives).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include "ExactMesh.hpp"

namespace rubble::detail::exact {

double toDouble(const K::FT& x) {
    const auto& a = x.approx();
    if (a.inf() == a.sup())
        return a.inf();
    return CGAL::to_double(x.exact());
}

void addMesh(const Mesh& mesh, SM& sm, const std::function<void(std::size_t, SM::Face_index)>& onFace) {
    sm.reserve(static_cast<SM::size_type>(sm.number_of_vertices() + mesh.positions.size()),
               static_cast<SM::size_type>(sm.number_of_edges() + mesh.triangles.size() * 3 / 2),
               static_cast<SM::size_type>(sm.number_of_faces() + mesh.triangles.size()));
    const auto first = static_cast<std::uint32_t>(sm.number_of_vertices());
    for (const Vec3& p : mesh.positions)
        sm.add_vertex(K::Point_3(p.x, p.y, p.z));
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        const SM::Face_index f =
            sm.add_face(SM::Vertex_index(first + tri[0]), SM::Vertex_index(first + tri[1]),
                        SM::Vertex_index(first + tri[2]));
        if (f == SM::null_face())
            throw Failure{"the mesh is not a manifold surface (triangle " + std::to_string(t) + ")"};
        if (onFace)
            onFace(t, f);
    }
}

void addCell(const ConvexPolytope& cell, SM& sm, const std::function<void(SM::Face_index)>& onFace) {
    const SM::size_type facesBefore = sm.number_of_faces();
    std::map<std::tuple<double, double, double>, SM::Vertex_index> index;
    auto vertex = [&](const Vec3& p) {
        auto [it, inserted] = index.emplace(std::make_tuple(p.x, p.y, p.z), SM::Vertex_index());
        if (inserted)
            it->second = sm.add_vertex(K::Point_3(p.x, p.y, p.z));
        return it->second;
    };
    for (const PolytopeFaceView& face : cell.faces()) {
        std::vector<SM::Vertex_index> loop;
        for (const Vec3& c : face.corners) {
            const SM::Vertex_index v = vertex(c);
            if (loop.empty() || loop.back() != v)
                loop.push_back(v);
        }
        while (loop.size() > 1 && loop.front() == loop.back())
            loop.pop_back();
        if (loop.size() < 3)
            continue;
        std::size_t apex = 0;
        for (std::size_t i = 1; i < loop.size(); ++i)
            if (face.corners.size() == loop.size() &&
                std::make_tuple(face.corners[i].x, face.corners[i].y, face.corners[i].z) <
                    std::make_tuple(face.corners[apex].x, face.corners[apex].y, face.corners[apex].z))
                apex = i;
        std::rotate(loop.begin(), loop.begin() + static_cast<std::ptrdiff_t>(apex), loop.end());
        // Triangles: the double corners of a face need not be exactly coplanar, and Nef needs planar faces.
        for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
            const SM::Face_index f = sm.add_face(loop[0], loop[i], loop[i + 1]);
            if (f == SM::null_face())
                throw Failure{"a cell is not a closed convex polytope"};
            if (onFace)
                onFace(f);
        }
    }
    if (sm.number_of_faces() < facesBefore + 4 || !CGAL::is_closed(sm))
        throw Failure{"a cell is not closed"};
}

void toTriangles(const SM& sm, std::vector<Vec3>& positions, std::vector<Triangle>& triangles,
                 const std::function<void(SM::Face_index)>& onFace) {
    std::vector<std::uint32_t> local(sm.num_vertices(), 0xFFFFFFFFu);
    triangles.reserve(triangles.size() + sm.number_of_faces());
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
        triangles.push_back(tri);
        if (onFace)
            onFace(f);
    }
}

} // namespace rubble::detail::exact
