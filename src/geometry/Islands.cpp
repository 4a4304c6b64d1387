#include "rubble/Islands.hpp"

#include <algorithm>
#include <numeric>
#include <unordered_map>

#include "rubble/MassProperties.hpp"

namespace rubble {

namespace {
struct UnionFind {
    std::vector<std::uint32_t> parent;
    explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    std::uint32_t find(std::uint32_t x) {
        while (parent[x] != x)
            x = parent[x] = parent[parent[x]];
        return x;
    }
    void unite(std::uint32_t a, std::uint32_t b) {
        a = find(a);
        b = find(b);
        if (a != b)
            parent[std::max(a, b)] = std::min(a, b); // smaller index wins: deterministic labels
    }
};

std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    if (a > b)
        std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | b;
}

// Parity of crossings of a ray from p along a fixed, slightly irrational direction.
bool insideByRay(const Mesh& m, const std::vector<std::size_t>& tris, const Vec3& p) {
    const Vec3 d = normalized(Vec3{0.5773502691896258, 0.5772502691896258, 0.5774502691896258});
    int crossings = 0;
    for (std::size_t t : tris) {
        const auto c = m.corners(t);
        const Vec3 e1 = c[1] - c[0], e2 = c[2] - c[0];
        const Vec3 h = cross(d, e2);
        const double a = dot(e1, h);
        if (a == 0)
            continue;
        const double f = 1.0 / a;
        const Vec3 s = p - c[0];
        const double u = f * dot(s, h);
        if (u < 0 || u > 1)
            continue;
        const Vec3 q = cross(s, e1);
        const double v = f * dot(d, q);
        if (v < 0 || u + v > 1)
            continue;
        if (f * dot(e2, q) > 0)
            ++crossings;
    }
    return crossings % 2 == 1;
}
} // namespace

std::size_t labelShells(const Mesh& mesh, std::vector<std::uint32_t>& triangleShell) {
    const std::size_t n = mesh.triangles.size();
    UnionFind uf(n);
    std::unordered_map<std::uint64_t, std::uint32_t> firstOwner;
    firstOwner.reserve(n * 3);
    for (std::uint32_t t = 0; t < n; ++t)
        for (int c = 0; c < 3; ++c) {
            const auto key = edgeKey(mesh.triangles[t][c], mesh.triangles[t][(c + 1) % 3]);
            auto [it, inserted] = firstOwner.emplace(key, t);
            if (!inserted)
                uf.unite(it->second, t);
        }
    triangleShell.assign(n, 0);
    std::vector<std::uint32_t> rootToLabel(n, UINT32_MAX);
    std::uint32_t count = 0;
    for (std::uint32_t t = 0; t < n; ++t) {
        const std::uint32_t r = uf.find(t);
        if (rootToLabel[r] == UINT32_MAX)
            rootToLabel[r] = count++;
        triangleShell[t] = rootToLabel[r];
    }
    return count;
}

std::vector<Mesh> splitIntoIslands(const Mesh& mesh) {
    std::vector<std::uint32_t> shellOf;
    const std::size_t shells = labelShells(mesh, shellOf);
    if (shells <= 1)
        return shells == 0 ? std::vector<Mesh>{} : std::vector<Mesh>{mesh};

    std::vector<std::vector<std::size_t>> trisOf(shells);
    for (std::size_t t = 0; t < shellOf.size(); ++t)
        trisOf[shellOf[t]].push_back(t);

    // Signed volume per shell decides outer shells (positive) and cavities (negative).
    std::vector<double> vol(shells, 0.0);
    const Vec3 r = mesh.bounds().center();
    for (std::size_t s = 0; s < shells; ++s)
        for (std::size_t t : trisOf[s]) {
            const auto c = mesh.corners(t);
            vol[s] += dot(c[0] - r, cross(c[1] - r, c[2] - r)) / 6.0;
        }
    std::vector<std::uint32_t> owner(shells);
    std::iota(owner.begin(), owner.end(), 0u);
    for (std::size_t s = 0; s < shells; ++s) {
        if (vol[s] >= 0)
            continue;
        // A cavity: attach to the smallest positive shell containing one of its vertices.
        const Vec3 probe = mesh.positions[mesh.triangles[trisOf[s][0]][0]];
        double best = 0;
        for (std::size_t o = 0; o < shells; ++o)
            if (vol[o] > 0 && (best == 0 || vol[o] < best) && insideByRay(mesh, trisOf[o], probe)) {
                best = vol[o];
                owner[s] = static_cast<std::uint32_t>(o);
            }
    }

    std::vector<Mesh> out;
    std::vector<std::int64_t> islandOf(shells, -1);
    for (std::size_t s = 0; s < shells; ++s) {
        const std::uint32_t o = owner[s];
        if (islandOf[o] < 0) {
            islandOf[o] = static_cast<std::int64_t>(out.size());
            out.emplace_back();
        }
        islandOf[s] = islandOf[o];
    }
    for (Mesh& m : out) {
        m.positions = mesh.positions;
        m.materialNames = mesh.materialNames;
    }
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        Mesh& m = out[static_cast<std::size_t>(islandOf[shellOf[t]])];
        m.triangles.push_back(mesh.triangles[t]);
        if (mesh.hasNormals())
            m.normals.insert(m.normals.end(), mesh.normals.begin() + 3 * t, mesh.normals.begin() + 3 * t + 3);
        if (mesh.hasUvs())
            m.uvs.insert(m.uvs.end(), mesh.uvs.begin() + 3 * t, mesh.uvs.begin() + 3 * t + 3);
        if (mesh.hasMaterials())
            m.materials.push_back(mesh.materials[t]);
    }
    for (Mesh& m : out)
        m.removeUnreferencedVertices();
    return out;
}

} // namespace rubble
