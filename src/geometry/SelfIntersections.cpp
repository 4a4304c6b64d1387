// The only translation unit of the mesh checks that includes CGAL (expensive to compile).
#include <algorithm>
#include <exception>
#include <iterator>
#include <string>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include "rubble/geometry/MeshCheck.hpp"

namespace rubble {

namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using FaceIndex = SurfaceMesh::Face_index;
namespace PMP = CGAL::Polygon_mesh_processing;

// CGAL tests every pair of triangles around a shared vertex (their boxes overlap) and looks the shared vertex
// up in a star walk each time: around a vertex of valence k that is k^2 pairs of O(k) work (a 3,000-triangle
// fan took 1.7 s, a 100,000-corner face over 100 s). Above this valence the test is skipped and the report
// says so.
constexpr std::size_t kMaxValence = 2048;

// Checks the preconditions of the CGAL test in plain C++ so that CGAL never sees malformed input.
std::string preconditionProblem(const Mesh& mesh) {
    for (const Vec3& p : mesh.positions)
        if (!isFinite(p))
            return "skipped: the mesh has non-finite coordinates";
    std::vector<std::size_t> valence(mesh.positions.size(), 0);
    for (const Triangle& t : mesh.triangles) {
        for (std::uint32_t v : t)
            if (v >= mesh.positions.size())
                return "skipped: a triangle refers to a vertex that does not exist";
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            return "skipped: the mesh has degenerate triangles";
        for (std::uint32_t v : t)
            ++valence[v];
    }
    const auto most = std::max_element(valence.begin(), valence.end());
    if (most != valence.end() && *most > kMaxValence)
        return "skipped: vertex " + std::to_string(most - valence.begin()) + " is shared by " +
               std::to_string(*most) + " triangles, more than " + std::to_string(kMaxValence) +
               " (the test takes quadratic time around such a vertex)";
    return {};
}
} // namespace

SelfIntersectionResult findSelfIntersections(const Mesh& mesh, std::size_t maxPairs) {
    SelfIntersectionResult result;
    if (mesh.triangles.empty()) {
        result.ran = true;
        return result;
    }
    if (std::string why = preconditionProblem(mesh); !why.empty()) {
        result.note = std::move(why);
        return result;
    }
    try {
        std::vector<Point> points;
        points.reserve(mesh.positions.size());
        for (const Vec3& p : mesh.positions)
            points.emplace_back(p.x, p.y, p.z);
        std::vector<std::vector<std::size_t>> polygons;
        polygons.reserve(mesh.triangles.size());
        for (const Triangle& t : mesh.triangles)
            polygons.push_back({t[0], t[1], t[2]});

        if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
            // Inconsistent orientation is fine for this test; re-orient a copy. When CGAL has to duplicate
            // vertices (non-manifold edges or vertices), touching triangles would be misreported: skip.
            const std::size_t before = points.size();
            const bool clean = PMP::orient_polygon_soup(points, polygons);
            if (!clean || points.size() != before || !PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
                result.note = "skipped: the mesh is not a manifold polygon mesh";
                return result;
            }
        }
        SurfaceMesh sm;
        PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
        if (sm.number_of_faces() != mesh.triangles.size()) {
            result.note = "skipped: the mesh could not be converted to a polygon mesh";
            return result;
        }
        std::vector<std::pair<FaceIndex, FaceIndex>> pairs;
        const auto limit = static_cast<unsigned int>(std::min<std::size_t>(maxPairs, 0xFFFFFFFFu));
        PMP::self_intersections(sm, std::back_inserter(pairs), CGAL::parameters::maximum_number(limit));
        for (const auto& [a, b] : pairs) {
            if (a == b) // a degenerate (collinear) face, reported by CGAL as (f, f)
                continue;
            ++result.pairs;
            if (result.examples.size() < 5) {
                const auto ia = static_cast<std::size_t>(a.idx()), ib = static_cast<std::size_t>(b.idx());
                result.examples.emplace_back(std::min(ia, ib), std::max(ia, ib));
            }
        }
        result.capped = maxPairs > 0 && pairs.size() >= maxPairs;
        result.ran = true;
    } catch (const std::exception& e) {
        result = {};
        result.note = std::string("failed: the geometric kernel reported: ") + e.what();
    } catch (...) {
        result = {};
        result.note = "failed: the geometric kernel reported an unknown error";
    }
    return result;
}

} // namespace rubble
