#include "rubble/geometry/MeshRepair.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <unordered_map>

#include "geometry/OrientedShells.hpp"
#include "geometry/PlanarTriangulation.hpp"
#include "geometry/RayParity.hpp"

namespace rubble {

namespace {
std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    if (a > b)
        std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | b;
}

std::string plural(std::size_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

// Keeps the triangles (and their attributes) for which keep[t] is true.
void filterTriangles(Mesh& m, const std::vector<bool>& keep) {
    std::size_t out = 0;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
        if (!keep[t])
            continue;
        m.triangles[out] = m.triangles[t];
        if (m.hasNormals())
            for (int c = 0; c < 3; ++c)
                m.normals[3 * out + c] = m.normals[3 * t + c];
        if (m.hasUvs())
            for (int c = 0; c < 3; ++c)
                m.uvs[3 * out + c] = m.uvs[3 * t + c];
        if (m.hasMaterials())
            m.materials[out] = m.materials[t];
        ++out;
    }
    m.triangles.resize(out);
    if (m.hasNormals())
        m.normals.resize(3 * out);
    if (m.hasUvs())
        m.uvs.resize(3 * out);
    if (m.hasMaterials())
        m.materials.resize(out);
}

// Reverses triangle t; normals that then point against the face are negated.
void flipTriangle(Mesh& m, std::size_t t) {
    std::swap(m.triangles[t][1], m.triangles[t][2]);
    if (m.hasUvs())
        std::swap(m.uvs[3 * t + 1], m.uvs[3 * t + 2]);
    if (m.hasNormals()) {
        std::swap(m.normals[3 * t + 1], m.normals[3 * t + 2]);
        const Vec3 n = m.triangleNormal(t);
        for (int c = 0; c < 3; ++c)
            if (dot(m.normals[3 * t + c], n) < 0)
                m.normals[3 * t + c] = Vec3f(-Vec3(m.normals[3 * t + c]));
    }
}

// Merges vertices closer than tol (in index order: each vertex joins the earliest vertex within tol).
// Returns the representative of every vertex.
std::vector<std::uint32_t> weldVertices(const Mesh& m, double tol) {
    const std::size_t n = m.positions.size();
    std::vector<std::uint32_t> rep(n);
    Aabb box;
    for (const Vec3& p : m.positions)
        if (isFinite(p))
            box.extend(p);
    struct CellHash {
        std::size_t operator()(const std::array<std::int64_t, 3>& c) const {
            return static_cast<std::size_t>((c[0] * 73856093) ^ (c[1] * 19349663) ^ (c[2] * 83492791));
        }
    };
    if (!(tol > 0) || box.empty()) {
        // Exact duplicates only.
        struct PosHash {
            std::size_t operator()(const std::array<double, 3>& p) const {
                std::size_t h = 0;
                for (double d : p)
                    h = h * 1000003u ^ std::hash<double>()(d == 0 ? 0.0 : d);
                return h;
            }
        };
        std::unordered_map<std::array<double, 3>, std::uint32_t, PosHash> first;
        first.reserve(n);
        for (std::uint32_t i = 0; i < n; ++i) {
            const Vec3& p = m.positions[i];
            rep[i] = i;
            if (!isFinite(p))
                continue;
            rep[i] = first.emplace(std::array<double, 3>{p.x + 0.0, p.y + 0.0, p.z + 0.0}, i).first->second;
        }
        return rep;
    }
    // Grid of cells of size tol relative to the box corner: candidates are in the 27 neighbouring cells.
    std::unordered_map<std::array<std::int64_t, 3>, std::vector<std::uint32_t>, CellHash> grid;
    grid.reserve(n);
    const double tol2 = tol * tol;
    auto cellOf = [&](const Vec3& p) {
        const Vec3 q = (p - box.lo) / tol;
        return std::array<std::int64_t, 3>{static_cast<std::int64_t>(std::floor(q.x)),
                                           static_cast<std::int64_t>(std::floor(q.y)),
                                           static_cast<std::int64_t>(std::floor(q.z))};
    };
    for (std::uint32_t i = 0; i < n; ++i) {
        const Vec3& p = m.positions[i];
        rep[i] = i;
        if (!isFinite(p))
            continue;
        const auto c = cellOf(p);
        std::uint32_t best = i;
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
                    if (it == grid.end())
                        continue;
                    for (std::uint32_t j : it->second)
                        if (j < best && lengthSquared(m.positions[j] - p) <= tol2)
                            best = j;
                }
        if (best != i) {
            rep[i] = best;
        } else {
            grid[c].push_back(i);
        }
    }
    return rep;
}

struct OrientStats {
    std::size_t flipped = 0, inverted = 0, nonOrientable = 0;
};

// Orients every component (connected through edges with exactly two triangles) consistently by a
// breadth-first walk, then outward by signed volume, or inward when nested inside an odd number of closed
// components (a cavity).
OrientStats orientShells(Mesh& m) {
    OrientStats stats;
    const std::size_t nt = m.triangles.size();
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> edgeTris;
    edgeTris.reserve(nt * 2);
    for (std::uint32_t t = 0; t < nt; ++t)
        for (int c = 0; c < 3; ++c)
            edgeTris[edgeKey(m.triangles[t][c], m.triangles[t][(c + 1) % 3])].push_back(t);

    auto usesDirected = [&](std::uint32_t t, std::uint32_t a, std::uint32_t b) {
        const Triangle& tri = m.triangles[t];
        for (int c = 0; c < 3; ++c)
            if (tri[c] == a && tri[(c + 1) % 3] == b)
                return true;
        return false;
    };

    std::vector<std::int32_t> comp(nt, -1);
    std::vector<std::vector<std::size_t>> comps;
    std::vector<bool> compClosed;
    for (std::uint32_t seed = 0; seed < nt; ++seed) {
        if (comp[seed] >= 0)
            continue;
        const auto id = static_cast<std::int32_t>(comps.size());
        comps.emplace_back();
        bool closed = true, conflict = false;
        std::deque<std::uint32_t> queue{seed};
        comp[seed] = id;
        while (!queue.empty()) {
            const std::uint32_t t = queue.front();
            queue.pop_front();
            comps.back().push_back(t);
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t a = m.triangles[t][c], b = m.triangles[t][(c + 1) % 3];
                const auto& around = edgeTris[edgeKey(a, b)];
                if (around.size() != 2) {
                    closed = false;
                    continue;
                }
                const std::uint32_t o = around[0] == t ? around[1] : around[0];
                const bool consistent = usesDirected(o, b, a);
                if (comp[o] < 0) {
                    comp[o] = id;
                    if (!consistent) {
                        flipTriangle(m, o);
                        ++stats.flipped;
                    }
                    queue.push_back(o);
                } else if (!consistent) {
                    conflict = true;
                }
            }
        }
        compClosed.push_back(closed && !conflict);
        if (conflict)
            ++stats.nonOrientable;
    }

    // Outward: compare the sign of each component's volume with its nesting depth among closed components.
    const detail::ShellNesting nesting = detail::shellNesting(m, comps, &compClosed);
    for (std::size_t i = 0; i < comps.size(); ++i) {
        if (nesting.volume[i] == 0)
            continue;
        const bool wantPositive = nesting.depth[i] % 2 == 0;
        if ((nesting.volume[i] > 0) != wantPositive) {
            for (std::size_t t : comps[i])
                flipTriangle(m, t);
            ++stats.inverted;
        }
    }
    return stats;
}

/// A hole's boundary may bend out of its best-fit plane by at most this fraction of its width to be filled.
constexpr double kHolePlanarity = 0.05;

struct HoleStats {
    std::size_t filled = 0;           // loops closed
    std::size_t triangles = 0;        // triangles added
    std::vector<std::string> reasons; // one per loop left open
};

// Closes the boundary loops that are simple and planar or nearly so: each by a constrained triangulation in
// its best-fit plane, the new triangles facing like their neighbours (the mesh is oriented consistently
// first). New triangles take the material of a neighbour, zero UVs and the plane's normal.
HoleStats fillHoles(Mesh& m) {
    HoleStats stats;
    std::unordered_map<std::uint64_t, int> uses; // triangles at each undirected edge
    for (const Triangle& t : m.triangles)
        for (int c = 0; c < 3; ++c)
            ++uses[edgeKey(t[c], t[(c + 1) % 3])];
    // The fill runs each boundary edge backwards: a -> b in its triangle is b -> a in the hole.
    std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> next;
    std::unordered_map<std::uint32_t, std::size_t> triangleAt; // a triangle on the boundary at each vertex
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t a = m.triangles[t][c], b = m.triangles[t][(c + 1) % 3];
            if (uses[edgeKey(a, b)] == 1) {
                next[b].push_back(a);
                triangleAt[b] = t;
            }
        }
    std::vector<std::uint32_t> starts;
    for (const auto& [v, out] : next)
        starts.push_back(v);
    std::sort(starts.begin(), starts.end()); // deterministic order of the loops
    std::unordered_map<std::uint32_t, bool> done;
    for (std::uint32_t start : starts) {
        if (done[start])
            continue;
        std::vector<std::uint32_t> loop;
        bool simple = true;
        for (std::uint32_t v = start;;) {
            done[v] = true;
            loop.push_back(v);
            const auto it = next.find(v);
            if (it == next.end() || it->second.size() != 1 || loop.size() > next.size()) {
                simple = false;
                break;
            }
            v = it->second.front();
            if (v == start)
                break;
            if (done[v]) {
                simple = false;
                break;
            }
        }
        if (!simple) {
            stats.reasons.push_back("a hole whose boundary is not one simple loop (at vertex " +
                                    std::to_string(start) + ")");
            continue;
        }
        // Best-fit (Newell) plane and how far the loop bends out of it.
        Vec3 normal{}, centre{};
        Aabb box;
        for (std::size_t i = 0; i < loop.size(); ++i) {
            const Vec3& p = m.positions[loop[i]];
            normal = normal + cross(p, m.positions[loop[(i + 1) % loop.size()]]);
            centre = centre + p;
            box.extend(p);
        }
        centre = centre / static_cast<double>(loop.size());
        const double width = box.diagonal();
        if (!(length(normal) > 0) || !(width > 0)) {
            stats.reasons.push_back("a hole of " + std::to_string(loop.size()) +
                                    " edges that encloses no area");
            continue;
        }
        const Vec3 n = normalized(normal);
        double bend = 0;
        for (std::uint32_t v : loop)
            bend = std::max(bend, std::abs(dot(m.positions[v] - centre, n)));
        if (bend > kHolePlanarity * width) {
            stats.reasons.push_back("a hole of " + std::to_string(loop.size()) +
                                    " edges that is not planar (it bends " +
                                    std::to_string(static_cast<int>(std::lround(100 * bend / width))) +
                                    "% of its width out of its plane)");
            continue;
        }
        std::vector<detail::RegionEdge> edges;
        for (std::size_t i = 0; i < loop.size(); ++i)
            edges.push_back({loop[i], loop[(i + 1) % loop.size()], 1});
        std::vector<std::array<std::uint32_t, 3>> tris;
        const char* failure = detail::triangulatePlanarRegion(
            edges, n, [&](std::uint32_t v) { return m.positions[v]; }, tris);
        if (failure || tris.size() != loop.size() - 2) {
            stats.reasons.push_back("a hole of " + std::to_string(loop.size()) +
                                    " edges whose outline crosses itself seen from its plane");
            continue;
        }
        const std::size_t neighbour = triangleAt[start];
        for (const auto& t : tris) {
            m.triangles.push_back({t[0], t[1], t[2]});
            if (m.hasNormals())
                for (int c = 0; c < 3; ++c)
                    m.normals.emplace_back(n);
            if (m.hasUvs())
                for (int c = 0; c < 3; ++c)
                    m.uvs.push_back(Vec2f{0, 0});
            if (m.hasMaterials())
                m.materials.push_back(m.materials[neighbour]);
        }
        stats.triangles += tris.size();
        ++stats.filled;
    }
    return stats;
}
} // namespace

RepairReport repairMesh(Mesh& mesh, const RepairOptions& options) {
    RepairReport rep;
    // Attribute arrays of the wrong size cannot be kept consistent: drop them.
    if (mesh.hasNormals() && mesh.normals.size() != 3 * mesh.triangles.size()) {
        mesh.normals.clear();
        rep.fixed.push_back("dropped normals whose count did not match the triangles");
    }
    if (mesh.hasUvs() && mesh.uvs.size() != 3 * mesh.triangles.size()) {
        mesh.uvs.clear();
        rep.fixed.push_back("dropped texture coordinates whose count did not match the triangles");
    }
    if (mesh.hasMaterials() && mesh.materials.size() != mesh.triangles.size()) {
        mesh.materials.clear();
        rep.fixed.push_back("dropped material ids whose count did not match the triangles");
    }

    // 1. Triangles with out-of-range indices or touching non-finite vertices.
    {
        std::vector<bool> keep(mesh.triangles.size(), true);
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
            bool bad = false, nonFinite = false;
            for (std::uint32_t v : mesh.triangles[t]) {
                if (v >= mesh.positions.size())
                    bad = true;
                else if (!isFinite(mesh.positions[v]))
                    nonFinite = true;
            }
            if (bad)
                ++rep.removedBadIndexTriangles;
            else if (nonFinite)
                ++rep.removedNonFiniteTriangles;
            keep[t] = !bad && !nonFinite;
        }
        if (rep.removedBadIndexTriangles + rep.removedNonFiniteTriangles > 0)
            filterTriangles(mesh, keep);
        if (rep.removedBadIndexTriangles > 0)
            rep.fixed.push_back(
                "removed " +
                plural(rep.removedBadIndexTriangles, "triangle that refers", "triangles that refer") +
                " to vertices that do not exist");
        if (rep.removedNonFiniteTriangles > 0)
            rep.fixed.push_back("removed " + plural(rep.removedNonFiniteTriangles, "triangle", "triangles") +
                                " touching vertices with non-finite coordinates (NaN or infinity)");
    }

    // 2. Weld vertices.
    {
        Aabb box;
        for (const Vec3& p : mesh.positions)
            if (isFinite(p))
                box.extend(p);
        const double tol = options.weldTolerance * box.diagonal();
        const std::vector<std::uint32_t> repOf = weldVertices(mesh, tol);
        for (std::size_t i = 0; i < repOf.size(); ++i)
            rep.weldedVertices += repOf[i] != i;
        if (rep.weldedVertices > 0) {
            for (Triangle& t : mesh.triangles)
                for (std::uint32_t& v : t)
                    v = repOf[v];
            rep.fixed.push_back("merged " +
                                plural(rep.weldedVertices, "duplicate vertex", "duplicate vertices"));
        }
    }

    // 3. Degenerate and duplicate triangles.
    {
        std::vector<bool> keep(mesh.triangles.size(), true);
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
            const Triangle& tri = mesh.triangles[t];
            if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] ||
                isDegenerateTriangle(mesh.positions[tri[0]], mesh.positions[tri[1]],
                                     mesh.positions[tri[2]])) {
                keep[t] = false;
                ++rep.removedDegenerate;
            }
        }
        std::vector<std::pair<std::array<std::uint32_t, 3>, std::size_t>> keyed;
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
            if (keep[t]) {
                std::array<std::uint32_t, 3> s = mesh.triangles[t];
                std::sort(s.begin(), s.end());
                keyed.emplace_back(s, t);
            }
        std::sort(keyed.begin(), keyed.end());
        for (std::size_t i = 1; i < keyed.size(); ++i)
            if (keyed[i].first == keyed[i - 1].first) {
                keep[keyed[i].second] = false;
                ++rep.removedDuplicates;
            }
        if (rep.removedDegenerate + rep.removedDuplicates > 0)
            filterTriangles(mesh, keep);
        if (rep.removedDegenerate > 0)
            rep.fixed.push_back("removed " +
                                plural(rep.removedDegenerate, "degenerate triangle", "degenerate triangles") +
                                " (repeated vertex or zero area)");
        if (rep.removedDuplicates > 0)
            rep.fixed.push_back("removed " +
                                plural(rep.removedDuplicates, "duplicate triangle", "duplicate triangles"));
    }

    // 4. Unreferenced vertices.
    {
        // Order-preserving compaction (Mesh::removeUnreferencedVertices renumbers by first use).
        std::vector<std::uint32_t> remap(mesh.positions.size(), 0);
        for (const Triangle& t : mesh.triangles)
            for (std::uint32_t v : t)
                remap[v] = 1;
        std::uint32_t kept = 0;
        for (std::size_t i = 0; i < remap.size(); ++i) {
            const bool used = remap[i] != 0;
            remap[i] = kept;
            if (used)
                mesh.positions[kept++] = mesh.positions[i];
            else
                ++rep.removedUnreferencedVertices;
        }
        mesh.positions.resize(kept);
        if (rep.removedUnreferencedVertices > 0)
            for (Triangle& t : mesh.triangles)
                for (std::uint32_t& v : t)
                    v = remap[v];
        if (rep.removedUnreferencedVertices > 0)
            rep.fixed.push_back("removed " +
                                plural(rep.removedUnreferencedVertices, "unused vertex", "unused vertices"));
    }

    // 5. Orientation.
    if (options.orient && !mesh.triangles.empty()) {
        const OrientStats s = orientShells(mesh);
        rep.flippedTriangles = s.flipped;
        rep.invertedShells = s.inverted;
        rep.nonOrientableShells = s.nonOrientable;
        if (s.flipped > 0)
            rep.fixed.push_back("flipped " + plural(s.flipped, "triangle", "triangles") +
                                " to agree with their neighbours");
        if (s.inverted > 0)
            rep.fixed.push_back("reversed " + plural(s.inverted, "inside-out shell", "inside-out shells"));
        if (s.nonOrientable > 0)
            rep.unrepaired.push_back(plural(s.nonOrientable, "shell cannot", "shells cannot") +
                                     " be oriented consistently (non-orientable surface)");
    }

    // 6. Holes, then the orientation of the shells they closed.
    if (options.fillHoles && options.orient && !mesh.triangles.empty()) {
        const HoleStats h = fillHoles(mesh);
        rep.filledHoles = h.filled;
        rep.openHoles = h.reasons.size();
        if (h.filled > 0) {
            rep.fixed.push_back("closed " + plural(h.filled, "hole", "holes") + " with " +
                                plural(h.triangles, "triangle", "triangles"));
            const OrientStats s = orientShells(mesh);
            rep.flippedTriangles += s.flipped;
            rep.invertedShells += s.inverted;
            if (s.inverted > 0)
                rep.fixed.push_back("reversed " + plural(s.inverted, "closed shell", "closed shells") +
                                    " to face outward");
        }
        for (const std::string& r : h.reasons)
            rep.unrepaired.push_back(
                "could not close " + r +
                ": close it in a modeller (e.g. Blender's Fill Holes, or a Remesh modifier)");
    }

    CheckOptions check;
    check.selfIntersections = options.checkSelfIntersections;
    rep.after = checkMesh(mesh, check);
    for (const std::string& p : rep.after.problems)
        rep.unrepaired.push_back(p);
    return rep;
}

} // namespace rubble
