#pragma once
// Independent invariant checks and test shapes shared by the fuzz targets and the stress test (no code from
// the library under test).

#include <cstdint>
#include <map>
#include <utility>

#include "rubble/geometry/Mesh.hpp"

namespace rubble::fuzz {

/// Closed, edge-manifold and consistently oriented: every directed edge exactly once, and its reverse too.
inline bool closedAndOriented(const Mesh& m) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (const Triangle& t : m.triangles)
        for (int c = 0; c < 3; ++c)
            if (t[c] == t[(c + 1) % 3] || ++directed[{t[c], t[(c + 1) % 3]}] > 1)
                return false;
    for (const auto& [e, count] : directed)
        if (!directed.count({e.second, e.first}))
            return false;
    return true;
}

/// Indices in range and attribute arrays of the right sizes. Unlike Mesh::validate(), non-finite coordinates
/// are allowed: readers keep them so that `rubble check` can name the vertex.
inline bool structurallyValid(const Mesh& m) {
    for (const Triangle& t : m.triangles)
        for (std::uint32_t v : t)
            if (v >= m.positions.size())
                return false;
    const std::size_t n = m.triangles.size();
    return (m.normals.empty() || m.normals.size() == 3 * n) && (m.uvs.empty() || m.uvs.size() == 3 * n) &&
           (m.materials.empty() || m.materials.size() == n);
}

/// A concave L-shaped prism (volume 3): the outline (0,0) (2,0) (2,1) (1,1) (1,2) (0,2) extruded from z = 0
/// to 1.
inline Mesh makeLShape() {
    static constexpr double outline[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
    static constexpr std::uint32_t cap[4][3] = {{0, 1, 2}, {0, 2, 3}, {0, 3, 5}, {3, 4, 5}};
    Mesh m;
    for (double z : {0.0, 1.0})
        for (const auto& xy : outline)
            m.positions.push_back({xy[0], xy[1], z});
    for (const auto& c : cap) {
        m.triangles.push_back({c[0], c[2], c[1]});             // bottom, facing -z
        m.triangles.push_back({c[0] + 6, c[1] + 6, c[2] + 6}); // top, facing +z
    }
    for (std::uint32_t a = 0, b = 1; a < 6; ++a, b = (a + 1) % 6) {
        m.triangles.push_back({a, b, b + 6});
        m.triangles.push_back({a, b + 6, a + 6});
    }
    return m;
}

} // namespace rubble::fuzz
