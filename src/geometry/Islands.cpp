#include "geometry/Islands.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>

#include "geometry/OrientedShells.hpp"
#include "geometry/RayParity.hpp"
#include "geometry/ShellScratch.hpp"
#include "rubble/geometry/MassProperties.hpp"

namespace rubble {

namespace {
struct UnionFind {
    std::vector<std::uint32_t>& parent; // its storage (reused between calls by closedOrientedShells)
    UnionFind(std::vector<std::uint32_t>& storage, std::size_t n) : parent(storage) {
        parent.resize(n);
        std::iota(parent.begin(), parent.end(), 0u);
    }
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

} // namespace

namespace {

/// Labels by the smallest triangle index of each union-find class, numbered in order of first appearance.
std::size_t labelsFrom(UnionFind& uf, std::vector<std::uint32_t>& triangleShell,
                       std::vector<std::uint32_t>& rootToLabel) {
    const std::size_t n = uf.parent.size();
    triangleShell.assign(n, 0);
    rootToLabel.assign(n, UINT32_MAX);
    std::uint32_t count = 0;
    for (std::uint32_t t = 0; t < n; ++t) {
        const std::uint32_t r = uf.find(t);
        if (rootToLabel[r] == UINT32_MAX)
            rootToLabel[r] = count++;
        triangleShell[t] = rootToLabel[r];
    }
    return count;
}

/// Sorts a vertex's neighbours: insertion sort for the usual handful, std::sort around high-valence vertices.
void sortShort(std::uint64_t* first, std::uint64_t* last) {
    if (last - first > 32) {
        std::sort(first, last);
        return;
    }
    for (std::uint64_t* i = first + 1; i < last; ++i) {
        const std::uint64_t key = *i;
        std::uint64_t* j = i;
        for (; j > first && j[-1] > key; --j)
            *j = j[-1];
        *j = key;
    }
}

/// The work arrays of closedOrientedShells, kept by each thread between calls: a million-triangle mesh needs
/// ~60 MB of them, and fresh allocations that large are mapped and faulted in again on every hit
/// (docs/megamesh.md). A thread keeps at most kKeepBytes; a larger call frees its arrays when it ends.
struct ShellScratch {
    static constexpr std::size_t kKeepBytes = std::size_t{96} << 20;
    std::vector<std::uint32_t> outFirst, inFirst, o, i, parent, rootToLabel;
    std::vector<std::uint64_t> out, in;
    std::size_t bytes() const {
        std::size_t b = 8 * (out.capacity() + in.capacity());
        for (const auto* v : {&outFirst, &inFirst, &o, &i, &parent, &rootToLabel})
            b += 4 * v->capacity();
        return b;
    }
};

/// Lends the calling thread's scratch for one call.
class ScratchLease {
public:
    ScratchLease() : s_(scratch()) {}
    ~ScratchLease() {
        if (s_.bytes() > ShellScratch::kKeepBytes)
            s_ = ShellScratch{};
    }
    ScratchLease(const ScratchLease&) = delete;
    ScratchLease& operator=(const ScratchLease&) = delete;
    ShellScratch& operator*() { return s_; }

private:
    static ShellScratch& scratch() {
        thread_local ShellScratch s;
        return s;
    }
    ShellScratch& s_;
    friend void detail::trimShellScratch(std::size_t);
    friend std::size_t detail::shellScratchBytes();
};

} // namespace

namespace detail {

std::size_t shellScratchBytes() {
    return ScratchLease::scratch().bytes();
}

void trimShellScratch(std::size_t keepBytes) {
    ShellScratch& s = ScratchLease::scratch();
    if (s.bytes() > keepBytes)
        s = ShellScratch{};
}

std::int64_t closedOrientedShells(const Mesh& mesh, std::vector<std::uint32_t>* triangleShell) {
    const std::size_t nv = mesh.positions.size(), nt = mesh.triangles.size();
    ScratchLease lease;
    ShellScratch& s = *lease;
    // Per vertex: outgoing (neighbour << 32 | triangle) and incoming (neighbour << 32 | triangle) entries.
    std::vector<std::uint32_t>&outFirst = s.outFirst, &inFirst = s.inFirst;
    outFirst.assign(nv + 1, 0);
    inFirst.assign(nv + 1, 0);
    for (const Triangle& t : mesh.triangles)
        for (int c = 0; c < 3; ++c) {
            if (t[c] >= nv)
                return -1;
            ++outFirst[t[c] + 1];
            ++inFirst[t[(c + 1) % 3] + 1];
        }
    for (std::size_t v = 0; v < nv; ++v) {
        outFirst[v + 1] += outFirst[v];
        inFirst[v + 1] += inFirst[v];
    }
    std::vector<std::uint64_t>&out = s.out, &in = s.in;
    out.resize(3 * nt); // every entry is written below
    in.resize(3 * nt);
    {
        std::vector<std::uint32_t>&o = s.o, &i = s.i;
        o.assign(outFirst.begin(), outFirst.end() - 1);
        i.assign(inFirst.begin(), inFirst.end() - 1);
        for (std::uint32_t t = 0; t < nt; ++t)
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t a = mesh.triangles[t][c], b = mesh.triangles[t][(c + 1) % 3];
                out[o[a]++] = std::uint64_t(b) << 32 | t;
                in[i[b]++] = std::uint64_t(a) << 32 | t;
            }
    }
    UnionFind uf(s.parent, triangleShell ? nt : 0);
    for (std::size_t v = 0; v < nv; ++v) {
        const std::uint32_t o0 = outFirst[v], o1 = outFirst[v + 1], i0 = inFirst[v];
        if (o1 - o0 != inFirst[v + 1] - i0)
            return -1;
        sortShort(out.data() + o0, out.data() + o1);
        sortShort(in.data() + i0, in.data() + i0 + (o1 - o0));
        for (std::uint32_t k = 0; k < o1 - o0; ++k) {
            const std::uint64_t e = out[o0 + k], r = in[i0 + k];
            const std::uint32_t to = static_cast<std::uint32_t>(e >> 32);
            // (v, to) must not be a loop or repeated, and its twin (to, v) must be the matching incoming
            // entry.
            if (to == v || (k > 0 && (out[o0 + k - 1] >> 32) == to) || (r >> 32) != to)
                return -1;
            if (triangleShell)
                uf.unite(static_cast<std::uint32_t>(e), static_cast<std::uint32_t>(r));
        }
    }
    if (!triangleShell)
        return 0;
    return static_cast<std::int64_t>(labelsFrom(uf, *triangleShell, s.rootToLabel));
}

} // namespace detail

std::size_t labelShells(const Mesh& mesh, std::vector<std::uint32_t>& triangleShell) {
    const std::size_t n = mesh.triangles.size(), nv = mesh.positions.size();
    std::vector<std::uint32_t> parent, rootToLabel;
    UnionFind uf(parent, n);
    // Triangles sharing an edge (either direction, also non-manifold) are united. Each half-edge is filed
    // under its smaller end; in one vertex's file, the first triangle seen on each other end is united with
    // the later ones (a stamp per other end), so the work is linear also around vertices of very high
    // valence.
    std::vector<std::uint32_t> first(nv + 1, 0);
    for (const Triangle& t : mesh.triangles)
        for (int c = 0; c < 3; ++c)
            ++first[std::min(t[c], t[(c + 1) % 3]) + 1];
    for (std::size_t v = 0; v < nv; ++v)
        first[v + 1] += first[v];
    std::vector<std::uint32_t> otherEnd(3 * n), triangleOf(3 * n);
    {
        std::vector<std::uint32_t> fill(first.begin(), first.end() - 1);
        for (std::uint32_t t = 0; t < n; ++t)
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t a = mesh.triangles[t][c], b = mesh.triangles[t][(c + 1) % 3];
                const std::uint32_t slot = fill[std::min(a, b)]++;
                otherEnd[slot] = std::max(a, b);
                triangleOf[slot] = t;
            }
    }
    std::vector<std::uint32_t> stamp(nv, UINT32_MAX), firstTriangle(nv, 0);
    for (std::uint32_t a = 0; a < nv; ++a)
        for (std::uint32_t k = first[a]; k < first[a + 1]; ++k) {
            const std::uint32_t b = otherEnd[k], t = triangleOf[k];
            if (stamp[b] == a) {
                uf.unite(firstTriangle[b], t);
            } else {
                stamp[b] = a;
                firstTriangle[b] = t;
            }
        }
    return labelsFrom(uf, triangleShell, rootToLabel);
}

namespace {

std::vector<Mesh> splitShells(const Mesh& mesh, const std::vector<std::uint32_t>& shellOf,
                              std::size_t shells) {
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
            if (vol[o] > 0 && (best == 0 || vol[o] < best) &&
                detail::insideByRayParity(mesh, trisOf[o], probe)) {
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
    // Vertices are numbered per island in order of first use (as removeUnreferencedVertices does); a vertex
    // shared by two islands (touching at a point) is copied into both.
    std::vector<std::uint32_t> local(mesh.positions.size(), UINT32_MAX);
    std::vector<std::size_t> localOwner(mesh.positions.size(), SIZE_MAX);
    for (Mesh& m : out)
        m.materialNames = mesh.materialNames;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto island = static_cast<std::size_t>(islandOf[shellOf[t]]);
        Mesh& m = out[island];
        Triangle tri = mesh.triangles[t];
        for (std::uint32_t& v : tri) {
            if (localOwner[v] != island) {
                localOwner[v] = island;
                local[v] = UINT32_MAX;
            }
            if (local[v] == UINT32_MAX) {
                local[v] = static_cast<std::uint32_t>(m.positions.size());
                m.positions.push_back(mesh.positions[v]);
            }
            v = local[v];
        }
        m.triangles.push_back(tri);
        if (mesh.hasNormals())
            m.normals.insert(m.normals.end(), mesh.normals.begin() + 3 * t, mesh.normals.begin() + 3 * t + 3);
        if (mesh.hasUvs())
            m.uvs.insert(m.uvs.end(), mesh.uvs.begin() + 3 * t, mesh.uvs.begin() + 3 * t + 3);
        if (mesh.hasMaterials())
            m.materials.push_back(mesh.materials[t]);
    }
    return out;
}

} // namespace

std::vector<Mesh> splitIntoIslands(const Mesh& mesh) {
    std::vector<std::uint32_t> shellOf;
    const std::size_t shells = labelShells(mesh, shellOf);
    if (shells <= 1)
        return shells == 0 ? std::vector<Mesh>{} : std::vector<Mesh>{mesh};
    return splitShells(mesh, shellOf, shells);
}

std::vector<Mesh> splitIntoIslands(Mesh&& mesh, const std::vector<std::uint32_t>& triangleShell,
                                   std::size_t shells) {
    std::vector<Mesh> out;
    if (shells == 1)
        out.push_back(std::move(mesh));
    else if (shells > 1)
        out = splitShells(mesh, triangleShell, shells);
    return out;
}

std::vector<Mesh> splitIntoIslands(Mesh&& mesh) {
    std::vector<std::uint32_t> shellOf;
    const std::size_t shells = labelShells(mesh, shellOf);
    return splitIntoIslands(std::move(mesh), shellOf, shells);
}

} // namespace rubble
