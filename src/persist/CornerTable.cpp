#include "persist/CornerTable.hpp"

#include <bit>

namespace rubble::persist {
namespace {

bool sameBits(const Vec3f& a, const Vec3f& b) {
    return std::bit_cast<std::uint32_t>(a.x) == std::bit_cast<std::uint32_t>(b.x) &&
           std::bit_cast<std::uint32_t>(a.y) == std::bit_cast<std::uint32_t>(b.y) &&
           std::bit_cast<std::uint32_t>(a.z) == std::bit_cast<std::uint32_t>(b.z);
}
bool sameBits(const Vec2f& a, const Vec2f& b) {
    return std::bit_cast<std::uint32_t>(a.x) == std::bit_cast<std::uint32_t>(b.x) &&
           std::bit_cast<std::uint32_t>(a.y) == std::bit_cast<std::uint32_t>(b.y);
}

} // namespace

CornerTable cornerTable(const Mesh& m, bool normals, bool uvs) {
    CornerTable t;
    const std::size_t n = 3 * m.triangles.size();
    t.codes.reserve(n);
    constexpr std::uint32_t kNone = ~std::uint32_t{0};
    std::vector<std::uint32_t> first(m.positions.size(), kNone); // a vertex's first corner
    std::vector<std::uint32_t> next;                             // the next corner of the same vertex
    std::uint32_t top = 0;                                       // corners so far
    for (std::size_t c = 0; c < n; ++c) {
        const std::uint32_t v = m.triangles[c / 3][c % 3];
        const std::uint32_t before = top;
        std::uint32_t k = first[v];
        while (k != kNone && !((!normals || sameBits(t.normals[k], m.normals[c])) &&
                               (!uvs || sameBits(t.uvs[k], m.uvs[c]))))
            k = next[k];
        if (k == kNone) {
            k = top++;
            t.vertex.push_back(v);
            if (normals)
                t.normals.push_back(m.normals[c]);
            if (uvs)
                t.uvs.push_back(m.uvs[c]);
            next.push_back(first[v]);
            first[v] = k;
        }
        t.codes.push_back(before - k);
    }
    return t;
}

CornerError checkCornerVertices(const CornerTable& t, std::size_t vertexCount) {
    for (std::size_t k = 0; k < t.vertex.size(); ++k)
        if (t.vertex[k] >= vertexCount)
            return {k, "vertex index " + std::to_string(t.vertex[k]) + " out of range (" +
                           std::to_string(vertexCount) + ")"};
    return {};
}

CornerError expandCorners(const CornerTable& t, std::size_t vertexCount, Mesh& m) {
    const std::size_t corners = t.vertex.size();
    if (!t.normals.empty() && t.normals.size() != corners)
        return {0, std::to_string(t.normals.size()) + " normals for " + std::to_string(corners) + " corners"};
    if (!t.uvs.empty() && t.uvs.size() != corners)
        return {0, std::to_string(t.uvs.size()) + " texture coordinates for " + std::to_string(corners) +
                       " corners"};
    if (t.codes.size() % 3 != 0)
        return {0, std::to_string(t.codes.size()) + " codes are not three per triangle"};
    m.triangles.assign(t.codes.size() / 3, Triangle{});
    m.normals.clear();
    m.uvs.clear();
    m.normals.reserve(t.normals.empty() ? 0 : t.codes.size());
    m.uvs.reserve(t.uvs.empty() ? 0 : t.codes.size());
    constexpr std::uint32_t kNone = ~std::uint32_t{0};
    std::vector<std::uint32_t> first(vertexCount, kNone), next(corners, kNone); // corners by vertex
    std::size_t top = 0;
    for (std::size_t c = 0; c < t.codes.size(); ++c) {
        const std::uint32_t code = t.codes[c];
        if (code > top || (code == 0 && top == corners))
            return {c, "code " + std::to_string(code) + " names no corner (" + std::to_string(top) +
                           " used of " + std::to_string(corners) + ")"};
        const std::size_t k = top - code;
        const std::uint32_t v = t.vertex[k];
        if (code == 0) {
            for (std::uint32_t j = first[v]; j != kNone; j = next[j])
                if ((t.normals.empty() || sameBits(t.normals[j], t.normals[k])) &&
                    (t.uvs.empty() || sameBits(t.uvs[j], t.uvs[k])))
                    return {c, "corner " + std::to_string(k) + " repeats corner " + std::to_string(j)};
            next[k] = first[v];
            first[v] = static_cast<std::uint32_t>(k);
            ++top;
        }
        m.triangles[c / 3][c % 3] = v;
        if (!t.normals.empty())
            m.normals.push_back(t.normals[k]);
        if (!t.uvs.empty())
            m.uvs.push_back(t.uvs[k]);
    }
    if (top != corners)
        return {t.codes.size(), std::to_string(corners - top) + " corners are never used"};
    return {};
}

} // namespace rubble::persist
