#include "rubble/geometry/MeshCheck.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <unordered_map>

#include "geometry/Islands.hpp"
#include "geometry/OrientedShells.hpp"
#include "geometry/RayParity.hpp"
#include "rubble/geometry/MassProperties.hpp"

namespace rubble {

namespace {
std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    if (a > b)
        std::swap(a, b);
    return (static_cast<std::uint64_t>(a) << 32) | b;
}

std::string num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

std::string plural(std::size_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

std::string edgeName(std::uint64_t key) {
    return std::to_string(key >> 32) + "-" + std::to_string(key & 0xFFFFFFFFu);
}

// " (a, b)" when the items are all there are, " (e.g. a, b, c)" when there are more than listed.
std::string examples(const std::vector<std::string>& items, std::size_t total) {
    if (items.empty())
        return {};
    std::string s = items.size() >= total ? " (" : " (e.g. ";
    for (std::size_t i = 0; i < items.size(); ++i)
        s += (i ? ", " : "") + items[i];
    return s + ")";
}

struct EdgeUse {
    std::uint32_t count = 0;   // incident triangles
    std::uint32_t forward = 0; // uses as low -> high
};
} // namespace

bool MeshReport::valid() const {
    return triangles > 0 && closed && edgeManifold && vertexManifold && oriented && outward &&
           degenerateTriangles == 0 && duplicateTriangles == 0 && nonFiniteVertices == 0 &&
           hugeVertices == 0 && badIndices == 0 && misnestedShells == 0 && badAttributeArrays == 0 &&
           !(selfIntersectionsChecked && selfIntersections > 0);
}

bool isDegenerateTriangle(const Vec3& a0, const Vec3& b0, const Vec3& c0) {
    // Scaled by a power of two (exact) to coordinates below 2, so that huge (1e300) or tiny (1e-300)
    // triangles neither overflow nor underflow; for ordinary ones the result is the same as without scaling.
    const double most =
        std::max({std::abs(a0.x), std::abs(a0.y), std::abs(a0.z), std::abs(b0.x), std::abs(b0.y),
                  std::abs(b0.z), std::abs(c0.x), std::abs(c0.y), std::abs(c0.z)});
    if (!std::isfinite(most))
        return false; // non-finite coordinates are reported as such
    const int shift = most > 0 ? -std::ilogb(most) : 0;
    auto scaled = [shift](const Vec3& p) {
        return Vec3{std::ldexp(p.x, shift), std::ldexp(p.y, shift), std::ldexp(p.z, shift)};
    };
    const Vec3 a = scaled(a0), b = scaled(b0), c = scaled(c0);
    const Vec3 e0 = b - a, e1 = c - a, e2 = c - b;
    const double longest = std::max({lengthSquared(e0), lengthSquared(e1), lengthSquared(e2)});
    if (longest == 0)
        return true;
    // Zero area relative to the longest edge (the sine of the largest angle's complement is below 1e-12).
    return lengthSquared(cross(e0, e1)) <= 1e-24 * longest * longest;
}

Status checkCoordinateRange(const Mesh& mesh, const std::string& what) {
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const Vec3& p = mesh.positions[i];
        const double most = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        if (most > kMaxCoordinate)
            return makeError(ErrorCode::InvalidInput,
                             what + ": vertex " + std::to_string(i) + " has a coordinate of " + num(most) +
                                 ", beyond ±" + num(kMaxCoordinate) +
                                 " (the bound that keeps the volume integrals finite); scale the mesh down");
    }
    return {};
}

namespace detail {
ShellNesting shellNesting(const Mesh& mesh, const std::vector<std::vector<std::size_t>>& trisOf,
                          const std::vector<bool>* closed) {
    const std::size_t k = trisOf.size();
    ShellNesting out{std::vector<double>(k, 0.0), std::vector<std::size_t>(k, 0)};
    std::vector<Aabb> box(k);
    const Vec3 r = mesh.bounds().center();
    for (std::size_t s = 0; s < k; ++s)
        for (std::size_t t : trisOf[s]) {
            const auto c = mesh.corners(t);
            out.volume[s] += dot(c[0] - r, cross(c[1] - r, c[2] - r)) / 6.0;
            for (const Vec3& p : c)
                box[s].extend(p);
        }
    auto takesPart = [&](std::size_t s) { return !trisOf[s].empty() && (!closed || (*closed)[s]); };
    // A shell can only be inside one whose box holds its box and differs from it (which keeps overlapping,
    // self-intersecting shells from being taken for cavities).
    auto contains = [](const Aabb& outer, const Aabb& inner) {
        return outer.contains(inner.lo) && outer.contains(inner.hi) &&
               !(outer.lo == inner.lo && outer.hi == inner.hi);
    };
    for (std::size_t s = 0; s < k; ++s) {
        if (!takesPart(s))
            continue;
        // Shells do not cross (else they intersect): one point of s tells whether s is inside another shell,
        // a triangle's centroid, since a vertex may be shared with a shell touching s there.
        const auto c = mesh.corners(trisOf[s][0]);
        const Vec3 probe = (c[0] + c[1] + c[2]) / 3.0;
        for (std::size_t o = 0; o < k; ++o)
            if (o != s && takesPart(o) && contains(box[o], box[s]) &&
                detail::insideByRayParity(mesh, trisOf[o], probe))
                ++out.depth[s];
    }
    return out;
}

std::size_t misnestedShells(const Mesh& mesh, const std::vector<std::uint32_t>& shellOf, std::size_t shells,
                            std::size_t maxListed, std::vector<std::string>& listed) {
    std::vector<std::vector<std::size_t>> trisOf(shells);
    for (std::size_t t = 0; t < shellOf.size(); ++t)
        trisOf[shellOf[t]].push_back(t);
    const ShellNesting nesting = shellNesting(mesh, trisOf);
    std::size_t wrong = 0;
    for (std::size_t s = 0; s < shells; ++s) {
        const std::size_t depth = nesting.depth[s];
        if ((depth % 2 == 1) == (nesting.volume[s] < 0))
            continue;
        ++wrong;
        if (listed.size() < maxListed)
            listed.push_back("the shell of triangle " + std::to_string(trisOf[s][0]) + " lies inside " +
                             plural(depth, "other shell", "other shells") + " and faces " +
                             (nesting.volume[s] < 0 ? "inward" : "outward"));
    }
    return wrong;
}
} // namespace detail

MeshReport checkMesh(const Mesh& mesh, const CheckOptions& options) {
    MeshReport r;
    r.vertices = mesh.positions.size();
    r.triangles = mesh.triangles.size();
    const std::size_t maxListed = options.maxListedPerKind;

    std::vector<std::string> nonFiniteEx, hugeEx, badIndexEx, degenerateEx, duplicateEx, misnestedEx;
    std::vector<bool> finite(mesh.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        finite[i] = isFinite(mesh.positions[i]);
        if (!finite[i]) {
            ++r.nonFiniteVertices;
            if (nonFiniteEx.size() < maxListed)
                nonFiniteEx.push_back("vertex " + std::to_string(i));
        } else {
            const Vec3& p = mesh.positions[i];
            const double most = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
            if (most > kMaxCoordinate) {
                ++r.hugeVertices;
                if (hugeEx.size() < maxListed)
                    hugeEx.push_back("vertex " + std::to_string(i) + " at " + num(most));
            }
            r.bounds.extend(mesh.positions[i]);
        }
    }

    // Triangles usable for topology: in range and three distinct indices.
    std::vector<bool> usable(mesh.triangles.size(), true);
    std::unordered_map<std::uint64_t, EdgeUse> edges;
    edges.reserve(mesh.triangles.size() * 2);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        bool inRange = true;
        for (std::uint32_t v : tri)
            if (v >= mesh.positions.size()) {
                inRange = false;
                ++r.badIndices;
                if (badIndexEx.size() < maxListed)
                    badIndexEx.push_back("triangle " + std::to_string(t) + " refers to vertex " +
                                         std::to_string(v) + " of " + std::to_string(mesh.positions.size()));
            }
        if (!inRange) {
            usable[t] = false;
            continue;
        }
        bool degenerate = tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2];
        if (!degenerate && finite[tri[0]] && finite[tri[1]] && finite[tri[2]])
            degenerate =
                isDegenerateTriangle(mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]);
        if (degenerate) {
            ++r.degenerateTriangles;
            if (degenerateEx.size() < maxListed)
                degenerateEx.push_back("triangle " + std::to_string(t));
        }
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
            usable[t] = false;
            continue;
        }
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t a = tri[c], b = tri[(c + 1) % 3];
            EdgeUse& e = edges[edgeKey(a, b)];
            ++e.count;
            if (a < b)
                ++e.forward;
        }
    }

    // Duplicate triangles (same vertex set), found by sorting the sorted triples.
    {
        std::vector<std::pair<std::array<std::uint32_t, 3>, std::size_t>> keyed;
        keyed.reserve(mesh.triangles.size());
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
            if (usable[t]) {
                std::array<std::uint32_t, 3> s = mesh.triangles[t];
                std::sort(s.begin(), s.end());
                keyed.emplace_back(s, t);
            }
        std::sort(keyed.begin(), keyed.end());
        for (std::size_t i = 1; i < keyed.size(); ++i)
            if (keyed[i].first == keyed[i - 1].first) {
                ++r.duplicateTriangles;
                if (duplicateEx.size() < maxListed)
                    duplicateEx.push_back("triangle " + std::to_string(keyed[i].second) +
                                          " repeats triangle " + std::to_string(keyed[i - 1].second));
            }
    }

    // Edge topology, examples in a deterministic order (smallest edge keys first).
    std::vector<std::uint64_t> openEx, nonManifoldEx, misorientedEx;
    std::vector<std::pair<std::uint64_t, EdgeUse>> sortedEdges(edges.begin(), edges.end());
    std::sort(sortedEdges.begin(), sortedEdges.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    std::unordered_map<std::uint64_t, std::uint32_t> nonManifoldCount;
    for (const auto& [key, use] : sortedEdges) {
        if (use.count == 1) {
            ++r.boundaryEdges;
            if (openEx.size() < maxListed)
                openEx.push_back(key);
        } else if (use.count == 2) {
            if (use.forward != 1) {
                ++r.misorientedEdges;
                if (misorientedEx.size() < maxListed)
                    misorientedEx.push_back(key);
            }
        } else {
            ++r.nonManifoldEdges;
            if (nonManifoldEx.size() < maxListed) {
                nonManifoldEx.push_back(key);
                nonManifoldCount[key] = use.count;
            }
        }
    }
    r.edgeManifold = r.nonManifoldEdges == 0;
    r.closed = r.boundaryEdges == 0 && r.nonManifoldEdges == 0 && !edges.empty();
    r.oriented = r.misorientedEdges == 0 && !edges.empty();

    // Vertex manifoldness: the link of each vertex (the edges opposite it) must be connected.
    std::vector<std::string> pinchedEx;
    if (r.badIndices == 0 && r.edgeManifold && !edges.empty()) {
        std::unordered_map<std::uint64_t, std::uint32_t> linkId; // (vertex, neighbour) -> union-find node
        linkId.reserve(mesh.triangles.size() * 6);
        std::vector<std::uint32_t> parent;
        auto node = [&](std::uint32_t v, std::uint32_t w) {
            const auto [it, inserted] =
                linkId.emplace((std::uint64_t{v} << 32) | w, static_cast<std::uint32_t>(parent.size()));
            if (inserted)
                parent.push_back(it->second);
            return it->second;
        };
        auto find = [&](std::uint32_t x) {
            while (parent[x] != x)
                x = parent[x] = parent[parent[x]];
            return x;
        };
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
            if (!usable[t])
                continue;
            const Triangle& tri = mesh.triangles[t];
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t v = tri[c], a = tri[(c + 1) % 3], b = tri[(c + 2) % 3];
                const std::uint32_t x = find(node(v, a)), y = find(node(v, b));
                if (x != y)
                    parent[std::max(x, y)] = std::min(x, y);
            }
        }
        std::unordered_map<std::uint32_t, std::uint32_t> firstRoot; // vertex -> a root of its link
        std::vector<std::uint32_t> pinched;
        for (const auto& [key, id] : linkId) {
            const auto v = static_cast<std::uint32_t>(key >> 32);
            const std::uint32_t root = find(id);
            const auto [it, inserted] = firstRoot.emplace(v, root);
            if (!inserted && it->second != root && it->second != UINT32_MAX) {
                it->second = UINT32_MAX; // counted once
                pinched.push_back(v);
            }
        }
        std::sort(pinched.begin(), pinched.end());
        r.nonManifoldVertices = pinched.size();
        for (std::size_t i = 0; i < pinched.size() && i < maxListed; ++i)
            pinchedEx.push_back("vertex " + std::to_string(pinched[i]));
    }
    r.vertexManifold = r.badIndices == 0 && r.edgeManifold && r.nonManifoldVertices == 0;

    if (r.badIndices == 0) {
        std::vector<std::uint32_t> shellOf;
        r.shells = labelShells(mesh, shellOf);
        if (r.shells > 1 && r.closed && r.oriented && r.nonManifoldVertices == 0 &&
            r.nonFiniteVertices == 0 && r.hugeVertices == 0)
            r.misnestedShells = detail::misnestedShells(mesh, shellOf, r.shells, maxListed, misnestedEx);
    }
    if (r.badIndices == 0 && r.nonFiniteVertices == 0 && !mesh.triangles.empty()) {
        const MassProperties mp = computeMassProperties(mesh);
        r.volume = mp.volume;
        r.centerOfMass = mp.centerOfMass;
    }
    r.outward = r.volume > 0;

    if (options.selfIntersections) {
        if (r.badIndices == 0 && r.nonFiniteVertices == 0 && r.degenerateTriangles == 0 && r.edgeManifold &&
            r.nonManifoldVertices == 0) {
            const SelfIntersectionResult si = findSelfIntersections(mesh, options.maxSelfIntersections);
            r.selfIntersectionsChecked = si.ran;
            r.selfIntersections = si.pairs;
            r.selfIntersectionsCapped = si.capped;
            r.selfIntersectionNote = si.note;
            if (si.pairs > 0) {
                std::vector<std::string> ex;
                for (const auto& [a, b] : si.examples)
                    if (ex.size() < maxListed)
                        ex.push_back("triangles " + std::to_string(a) + " and " + std::to_string(b));
                r.problems.push_back(
                    (si.capped ? "at least " : "") +
                    plural(si.pairs, "pair of triangles intersects", "pairs of triangles intersect") +
                    examples(ex, si.capped ? si.pairs + 1 : si.pairs));
            }
        } else {
            r.selfIntersectionNote = r.nonFiniteVertices > 0 ? "skipped: the mesh has non-finite coordinates"
                                     : r.badIndices > 0
                                         ? "skipped: a triangle refers to a vertex that does not exist"
                                     : r.degenerateTriangles  ? "skipped: the mesh has degenerate triangles"
                                     : r.nonManifoldEdges > 0 ? "skipped: the mesh has non-manifold edges"
                                                              : "skipped: the mesh has non-manifold vertices";
        }
    } else {
        r.selfIntersectionNote = "skipped on request";
    }

    // Problems, most fundamental first. The self-intersection problem (if any) goes after topology.
    std::vector<std::string> problems;
    if (mesh.triangles.empty())
        problems.push_back("the mesh has no triangles");
    if (r.nonFiniteVertices > 0)
        problems.push_back(plural(r.nonFiniteVertices, "vertex has", "vertices have") +
                           " a non-finite coordinate (NaN or infinity)" +
                           examples(nonFiniteEx, r.nonFiniteVertices));
    if (r.badIndices > 0)
        problems.push_back(plural(r.badIndices, "triangle corner refers", "triangle corners refer") +
                           " to a vertex that does not exist" + examples(badIndexEx, r.badIndices));
    auto attribute = [&](std::size_t have, std::size_t perTriangle, const char* what) {
        const std::size_t want = perTriangle * mesh.triangles.size();
        if (have == 0 || have == want)
            return;
        ++r.badAttributeArrays;
        problems.push_back(std::string(what) + " have " + std::to_string(have) + " entries but " +
                           std::to_string(want) + " are needed (" + std::to_string(perTriangle) +
                           " per triangle)");
    };
    attribute(mesh.normals.size(), 3, "normals");
    attribute(mesh.uvs.size(), 3, "texture coordinates");
    attribute(mesh.materials.size(), 1, "material ids");
    if (r.boundaryEdges > 0) {
        std::vector<std::string> ex;
        for (std::uint64_t k : openEx)
            ex.push_back("edge " + edgeName(k));
        problems.push_back(
            "the mesh is not closed (holes): " + plural(r.boundaryEdges, "edge is", "edges are") +
            " used by only one triangle" + examples(ex, r.boundaryEdges));
    }
    if (r.nonManifoldEdges > 0) {
        std::vector<std::string> ex;
        for (std::uint64_t k : nonManifoldEx)
            ex.push_back("edge " + edgeName(k) + " has " + std::to_string(nonManifoldCount[k]) +
                         " triangles");
        problems.push_back("the mesh is not manifold: " + plural(r.nonManifoldEdges, "edge is", "edges are") +
                           " shared by three or more triangles" + examples(ex, r.nonManifoldEdges));
    }
    if (r.nonManifoldVertices > 0)
        problems.push_back(
            "the mesh is not manifold: " + plural(r.nonManifoldVertices, "vertex joins", "vertices join") +
            " parts that share no edge there (pinched)" + examples(pinchedEx, r.nonManifoldVertices));
    if (r.misorientedEdges > 0) {
        std::vector<std::string> ex;
        for (std::uint64_t k : misorientedEx)
            ex.push_back("edge " + edgeName(k));
        problems.push_back("the mesh is not consistently oriented (flipped triangles): " +
                           plural(r.misorientedEdges, "edge is", "edges are") +
                           " used twice in the same direction" + examples(ex, r.misorientedEdges));
    }
    if (r.hugeVertices > 0)
        problems.push_back(plural(r.hugeVertices, "vertex has", "vertices have") + " a coordinate beyond ±" +
                           num(kMaxCoordinate) + ", the bound that keeps the volume integrals finite" +
                           examples(hugeEx, r.hugeVertices) + "; scale the mesh down");
    if (!mesh.triangles.empty() && r.badIndices == 0 && r.nonFiniteVertices == 0 && r.hugeVertices == 0 &&
        r.closed && r.oriented && !r.outward)
        problems.push_back(r.volume < 0 ? "the mesh is inside out (signed volume " + num(r.volume) + ")"
                                        : "the mesh encloses no volume");
    if (r.misnestedShells > 0)
        problems.push_back(plural(r.misnestedShells, "shell faces", "shells face") +
                           " the wrong way for its nesting: a shell inside another must face inward (a "
                           "cavity), one inside none outward" +
                           examples(misnestedEx, r.misnestedShells));
    if (r.degenerateTriangles > 0)
        problems.push_back(plural(r.degenerateTriangles, "triangle is", "triangles are") +
                           " degenerate (repeated vertex or zero area)" +
                           examples(degenerateEx, r.degenerateTriangles));
    if (r.duplicateTriangles > 0)
        problems.push_back(plural(r.duplicateTriangles, "triangle duplicates", "triangles duplicate") +
                           " an earlier triangle" + examples(duplicateEx, r.duplicateTriangles));
    problems.insert(problems.end(), r.problems.begin(), r.problems.end());
    r.problems = std::move(problems);
    return r;
}

} // namespace rubble
