#include "geometry/MeshTopology.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "geometry/TopologyEdit.hpp"

namespace rubble {

namespace {

constexpr std::uint32_t kNoTwin = 0xFFFFFFFFu;

std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t(a) << 32) | b;
}

/// Resizes v to n; when that reallocates, with room for 1/16 more, so that the next edits do not.
template <class T>
void growTo(std::vector<T>& v, std::size_t n) {
    if (n > v.capacity())
        v.reserve(n + n / 16);
    v.resize(n);
}

} // namespace

std::optional<MeshTopology> buildTopology(const Mesh& mesh) {
    const std::size_t nT = mesh.triangles.size();
    if (nT == 0 || 3 * nT >= kNoTwin)
        return std::nullopt;
    // Half-edges bucketed by their start vertex; a half-edge's twin is in its end's bucket.
    detail::CornersByVertex byStart;
    if (!byStart.buildAll(mesh))
        return std::nullopt;
    auto end = [&](std::uint32_t h) { return mesh.triangles[h / 3][(h % 3 + 1) % 3]; };
    MeshTopology topo;
    topo.twin.assign(3 * nT, kNoTwin);
    for (std::uint32_t h = 0; h < 3 * nT; ++h) {
        const std::uint32_t a = mesh.triangles[h / 3][h % 3], b = end(h);
        if (a == b)
            return std::nullopt;
        std::uint32_t found = kNoTwin, same = 0;
        for (std::uint32_t g : byStart.at(b))
            if (end(g) == a) {
                if (found != kNoTwin)
                    return std::nullopt; // the reverse twice
                found = g;
            }
        for (std::uint32_t g : byStart.at(a))
            same += end(g) == b ? 1u : 0u;
        if (found == kNoTwin || same != 1)
            return std::nullopt;
        topo.twin[h] = found;
    }
    // One shell: a walk over the twins reaches every triangle.
    std::vector<bool> seen(nT, false);
    std::vector<std::uint32_t> stack{0};
    seen[0] = true;
    std::size_t reached = 1;
    while (!stack.empty()) {
        const std::uint32_t t = stack.back();
        stack.pop_back();
        for (std::uint32_t c = 0; c < 3; ++c) {
            const std::uint32_t u = topo.twin[3 * t + c] / 3;
            if (!seen[u]) {
                seen[u] = true;
                ++reached;
                stack.push_back(u);
            }
        }
    }
    if (reached != nT)
        return std::nullopt;
    return topo;
}

namespace detail {

std::optional<std::vector<std::uint32_t>> replaceTriangles(Mesh& mesh, MeshTopology& topology,
                                                           std::span<const std::uint32_t> removed,
                                                           std::span<const Vec3> newPositions,
                                                           TriangleBatch&& added,
                                                           std::vector<std::uint32_t>* follow) {
    const std::size_t nT = mesh.triangles.size(), nA = added.triangles.size();
    const auto nV = static_cast<std::uint32_t>(mesh.positions.size());
    const bool hasN = mesh.hasNormals();
    if (!topology.fits(mesh) || mesh.uvs.size() != 3 * nT || mesh.materials.size() != nT ||
        added.uvs.size() != 3 * nA || added.materials.size() != nA ||
        added.normals.size() != (hasN ? 3 * nA : 0) || nT - removed.size() + nA >= kNoTwin / 3)
        return std::nullopt;
    for (const Vec3& p : newPositions)
        if (!isFinite(p))
            return std::nullopt;
    const std::size_t allV = nV + newPositions.size();
    // B: the removed triangles' directed edges; N: the added ones'. Conditions 1-4 of docs/megamesh.md.
    std::unordered_map<std::uint64_t, std::uint32_t> inB, inN;
    std::unordered_map<std::uint32_t, std::uint32_t> outOf; // vertex -> a removed half-edge leaving it
    inB.reserve(3 * removed.size());
    inN.reserve(3 * nA);
    for (std::size_t i = 0; i < removed.size(); ++i) {
        const std::uint32_t t = removed[i];
        if (t >= nT || (i > 0 && removed[i - 1] >= t))
            return std::nullopt;
        for (std::uint32_t c = 0; c < 3; ++c) {
            inB.emplace(edgeKey(mesh.triangles[t][c], mesh.triangles[t][(c + 1) % 3]), 3 * t + c);
            outOf.emplace(mesh.triangles[t][c], 3 * t + c);
        }
    }
    // Whether a kept triangle has the edge a->b: a walk around a from one of its removed half-edges.
    auto keptEdge = [&](std::uint32_t a, std::uint32_t b) {
        const auto start = outOf.find(a);
        if (start == outOf.end())
            return true; // a vertex no removed triangle has: its triangles are all kept
        std::uint32_t h = start->second;
        for (std::size_t steps = 0; steps < 3 * nT; ++steps) {
            const std::uint32_t t = h / 3;
            if (mesh.triangles[t][(h % 3 + 1) % 3] == b &&
                !std::binary_search(removed.begin(), removed.end(), t))
                return true;
            h = topology.twin[3 * t + (h % 3 + 2) % 3];
            if (h == start->second)
                return false;
        }
        return true;
    };
    for (std::uint32_t i = 0; i < nA; ++i)
        for (std::uint32_t c = 0; c < 3; ++c) {
            const std::uint32_t a = added.triangles[i][c], b = added.triangles[i][(c + 1) % 3];
            if (a >= allV || b >= allV || a == b || !inN.emplace(edgeKey(a, b), 3 * i + c).second)
                return std::nullopt; // out of range, a loop, or condition 1
            if (a < nV && b < nV && !inB.count(edgeKey(a, b)) && keptEdge(a, b))
                return std::nullopt; // condition 2
        }
    // Per added half-edge: its twin, 3i+c among the added (marked) or a kept half-edge.
    constexpr std::uint32_t kAddedBit = 0x80000000u;
    std::vector<std::uint32_t> twinOf(3 * nA);
    for (std::uint32_t i = 0; i < nA; ++i)
        for (std::uint32_t c = 0; c < 3; ++c) {
            const std::uint32_t a = added.triangles[i][c], b = added.triangles[i][(c + 1) % 3];
            if (auto r = inN.find(edgeKey(b, a)); r != inN.end()) {
                twinOf[3 * i + c] = r->second | kAddedBit;
                continue;
            }
            const auto e = inB.find(edgeKey(a, b));
            if (e == inB.end() || inB.count(edgeKey(b, a)))
                return std::nullopt; // condition 3
            twinOf[3 * i + c] = topology.twin[e->second];
        }
    for (const auto& [key, h] : inB)
        if (!inB.count(edgeKey(static_cast<std::uint32_t>(key & 0xFFFFFFFFu),
                               static_cast<std::uint32_t>(key >> 32))) &&
            !inN.count(key))
            return std::nullopt; // condition 4
    if (3 * nA >= kAddedBit)
        return std::nullopt;

    // Apply: slots for the added triangles, then the surplus slots filled from the end.
    const std::size_t oldV = mesh.positions.size();
    growTo(mesh.positions, oldV + newPositions.size());
    std::copy(newPositions.begin(), newPositions.end(),
              mesh.positions.begin() + static_cast<std::ptrdiff_t>(oldV));
    std::vector<std::uint32_t> slot(nA);
    for (std::size_t i = 0; i < nA; ++i)
        slot[i] = i < removed.size() ? removed[i] : static_cast<std::uint32_t>(nT + (i - removed.size()));
    const std::size_t total = nT - removed.size() + nA;
    if (total > nT) {
        growTo(mesh.triangles, total);
        growTo(mesh.uvs, 3 * total);
        growTo(mesh.materials, total);
        if (hasN)
            growTo(mesh.normals, 3 * total);
        growTo(topology.twin, 3 * total);
    }
    // Writes a triangle and its attributes into slot s.
    auto put = [&](std::uint32_t s, const Triangle& tri, std::uint32_t material, const Vec2f* uvs,
                   const Vec3f* normals) {
        mesh.triangles[s] = tri;
        mesh.materials[s] = material;
        std::copy(uvs, uvs + 3, mesh.uvs.begin() + 3 * s);
        if (hasN)
            std::copy(normals, normals + 3, mesh.normals.begin() + 3 * s);
    };
    for (std::size_t i = 0; i < nA; ++i) {
        const std::uint32_t s = slot[i];
        put(s, added.triangles[i], added.materials[i], &added.uvs[3 * i],
            hasN ? &added.normals[3 * i] : nullptr);
        for (std::uint32_t c = 0; c < 3; ++c) {
            const std::uint32_t t = twinOf[3 * i + c];
            if (t & kAddedBit) {
                const std::uint32_t j = (t & ~kAddedBit) / 3, d = (t & ~kAddedBit) % 3;
                topology.twin[3 * s + c] = 3 * slot[j] + d;
            } else {
                topology.twin[3 * s + c] = t;
                topology.twin[t] = 3 * s + c;
            }
        }
    }
    if (total < nT) {
        // Holes: surplus slots below the new end; movers: kept triangles at or above it.
        const std::span<const std::uint32_t> surplus = removed.subspan(nA);
        std::vector<std::uint32_t> holes, movers;
        for (std::uint32_t s : surplus)
            if (s < total)
                holes.push_back(s);
        std::size_t k = 0;
        for (auto t = static_cast<std::uint32_t>(total); t < nT; ++t) {
            while (k < surplus.size() && surplus[k] < t)
                ++k;
            if (k == surplus.size() || surplus[k] != t)
                movers.push_back(t);
        }
        for (std::size_t i = 0; i < holes.size(); ++i) {
            const std::uint32_t from = movers[i], to = holes[i];
            put(to, mesh.triangles[from], mesh.materials[from], &mesh.uvs[3 * from],
                hasN ? &mesh.normals[3 * from] : nullptr);
            for (std::uint32_t c = 0; c < 3; ++c) {
                const std::uint32_t t = topology.twin[3 * from + c];
                topology.twin[3 * to + c] = t;
                topology.twin[t] = 3 * to + c;
            }
        }
        if (follow && !holes.empty()) {
            std::unordered_map<std::uint32_t, std::uint32_t> moved; // mover -> hole
            for (std::size_t i = 0; i < holes.size(); ++i)
                moved.emplace(movers[i], holes[i]);
            for (std::uint32_t& s : *follow)
                if (auto it = moved.find(s); it != moved.end())
                    s = it->second;
        }
        mesh.triangles.resize(total);
        mesh.uvs.resize(3 * total);
        mesh.materials.resize(total);
        if (hasN)
            mesh.normals.resize(3 * total);
        topology.twin.resize(3 * total);
    }
    return slot;
}

bool stillOneShell(const Mesh& mesh, const MeshTopology& topology, std::span<const std::uint32_t> addedSlots,
                   const Aabb& near) {
    if (addedSlots.empty())
        return false;
    std::unordered_map<std::uint32_t, bool> seen; // triangle -> is an added one
    seen.reserve(4 * addedSlots.size());
    for (std::uint32_t s : addedSlots)
        seen.emplace(s, false);
    std::vector<std::uint32_t> stack{addedSlots.front()};
    seen[addedSlots.front()] = true;
    std::size_t reached = 1;
    while (!stack.empty() && reached < addedSlots.size()) {
        const std::uint32_t t = stack.back();
        stack.pop_back();
        for (std::uint32_t c = 0; c < 3; ++c) {
            const std::uint32_t u = topology.twin[3 * t + c] / 3;
            auto [it, fresh] = seen.emplace(u, true);
            if (!fresh) {
                if (it->second)
                    continue;
                it->second = true; // an added triangle, reached for the first time
                ++reached;
                stack.push_back(u);
                continue;
            }
            Aabb box;
            for (std::uint32_t v : mesh.triangles[u])
                box.extend(mesh.positions[v]);
            if (box.overlaps(near))
                stack.push_back(u);
        }
    }
    return reached == addedSlots.size();
}

std::vector<std::vector<std::uint32_t>> racingIslands(const MeshTopology& topology,
                                                      std::span<const std::uint32_t> addedSlots) {
    // Walk w starts at added triangle w; walks that meet merge (union-find, the longer queue kept).
    const std::size_t k = addedSlots.size();
    if (k == 0)
        return {};
    std::vector<std::uint32_t> parent(k);
    std::vector<std::vector<std::uint32_t>> queue(k);
    std::vector<std::size_t> head(k, 0), size(k, 1);
    // Triangle -> the walk that reached it first: hashed, dense once the walks reach 1/16 of the mesh.
    const std::size_t nT = topology.twin.size() / 3;
    std::unordered_map<std::uint32_t, std::uint32_t> sparse;
    std::vector<std::uint32_t> dense;
    sparse.reserve(8 * k);
    auto claim = [&](std::uint32_t t, std::uint32_t w) { // t's walk, or kNoTwin once w claimed it
        if (!dense.empty()) {
            std::uint32_t& o = dense[t];
            return o == kNoTwin ? (o = w, kNoTwin) : o;
        }
        auto [it, fresh] = sparse.emplace(t, w);
        if (!fresh)
            return it->second;
        if (sparse.size() > nT / 16) {
            dense.assign(nT, kNoTwin);
            for (const auto& [u, v] : sparse)
                dense[u] = v;
            sparse = {};
        }
        return kNoTwin;
    };
    for (std::uint32_t w = 0; w < k; ++w) {
        parent[w] = w;
        claim(addedSlots[w], w);
        queue[w].push_back(addedSlots[w]);
    }
    auto find = [&](std::uint32_t w) {
        while (parent[w] != w)
            w = parent[w] = parent[parent[w]];
        return w;
    };
    std::vector<std::uint32_t> live(k), exhausted;
    for (std::uint32_t w = 0; w < k; ++w)
        live[w] = w;
    std::size_t running = k;
    while (running > 1) { // one round: every running walk takes one triangle
        for (std::uint32_t w : live) {
            if (find(w) != w || head[w] == queue[w].size())
                continue; // merged away, or exhausted this round
            const std::uint32_t t = queue[w][head[w]++];
            for (std::uint32_t c = 0; c < 3; ++c) {
                const std::uint32_t u = topology.twin[3 * t + c] / 3;
                const std::uint32_t r = find(w), o = claim(u, r);
                if (o == kNoTwin) {
                    queue[r].push_back(u);
                    ++size[r];
                    continue;
                }
                const std::uint32_t s = find(o);
                if (s == r)
                    continue;
                // Two running walks meet (an exhausted one has no unwalked neighbour): merge into the
                // one with more left to walk.
                const bool keepR = queue[r].size() - head[r] >= queue[s].size() - head[s];
                const std::uint32_t into = keepR ? r : s, from = keepR ? s : r;
                queue[into].insert(queue[into].end(),
                                   queue[from].begin() + static_cast<std::ptrdiff_t>(head[from]),
                                   queue[from].end());
                std::vector<std::uint32_t>().swap(queue[from]);
                head[from] = 0;
                size[into] += size[from];
                parent[from] = into;
                --running;
            }
            const std::uint32_t r = find(w);
            if (head[r] == queue[r].size()) { // a complete shell: every neighbour of its triangles walked
                exhausted.push_back(r);
                --running;
            }
        }
        std::erase_if(live, [&](std::uint32_t w) { return find(w) != w || head[w] == queue[w].size(); });
    }
    // The shell kept in place: the running walk's, or the largest when all ran out.
    std::uint32_t keep = live.empty() ? exhausted.front() : live.front();
    for (std::uint32_t r : exhausted)
        if (live.empty() && size[r] > size[keep])
            keep = r;
    std::vector<std::uint32_t> index(k, 0xFFFFFFFFu);
    std::vector<std::vector<std::uint32_t>> out;
    for (std::uint32_t r : exhausted)
        if (r != keep) {
            index[r] = static_cast<std::uint32_t>(out.size());
            out.emplace_back();
        }
    auto collect = [&](std::uint32_t t, std::uint32_t w) {
        if (const std::uint32_t i = index[find(w)]; i != 0xFFFFFFFFu)
            out[i].push_back(t);
    };
    for (const auto& [t, w] : sparse)
        collect(t, w);
    for (std::uint32_t t = 0; t < dense.size(); ++t)
        if (dense[t] != kNoTwin)
            collect(t, dense[t]);
    for (auto& shell : out)
        std::sort(shell.begin(), shell.end());
    return out;
}

std::optional<Mesh> takeShells(Mesh& mesh, MeshTopology& topology, std::span<const std::uint32_t> slots,
                               std::vector<std::uint32_t>* follow) {
    Mesh out;
    const bool hasN = mesh.hasNormals();
    std::unordered_map<std::uint32_t, std::uint32_t> index;
    index.reserve(slots.size());
    for (std::uint32_t t : slots) {
        Triangle tri = mesh.triangles[t];
        for (std::uint32_t& v : tri) {
            auto [it, fresh] = index.emplace(v, static_cast<std::uint32_t>(out.positions.size()));
            if (fresh)
                out.positions.push_back(mesh.positions[v]);
            v = it->second;
        }
        out.triangles.push_back(tri);
        out.uvs.insert(out.uvs.end(), mesh.uvs.begin() + 3 * t, mesh.uvs.begin() + 3 * t + 3);
        out.materials.push_back(mesh.materials[t]);
        if (hasN)
            out.normals.insert(out.normals.end(), mesh.normals.begin() + 3 * t,
                               mesh.normals.begin() + 3 * t + 3);
    }
    // A closed shell has no boundary: its slots go with nothing in their place.
    if (!replaceTriangles(mesh, topology, slots, {}, TriangleBatch{}, follow))
        return std::nullopt;
    return out;
}

std::vector<std::uint32_t> trianglesAround(const Mesh& mesh, const MeshTopology& topology,
                                           std::span<const std::uint32_t> seeds) {
    std::vector<std::uint32_t> out;
    std::unordered_set<std::uint32_t> corners, taken;
    corners.reserve(2 * seeds.size());
    taken.reserve(4 * seeds.size());
    const std::size_t limit = mesh.triangles.size();
    for (std::uint32_t t : seeds)
        for (std::uint32_t c = 0; c < 3; ++c) {
            if (!corners.insert(mesh.triangles[t][c]).second)
                continue;
            const std::uint32_t start = 3 * t + c; // leaves corner c; the walk turns around it
            std::uint32_t h = start;
            for (std::size_t steps = 0; steps < limit; ++steps) {
                if (taken.insert(h / 3).second)
                    out.push_back(h / 3);
                h = topology.twin[3 * (h / 3) + (h % 3 + 2) % 3];
                if (h == start)
                    break;
            }
        }
    std::sort(out.begin(), out.end());
    return out;
}

void compactVerticesIfSparse(Mesh& mesh) {
    if (mesh.positions.size() > mesh.triangles.size() / 2 + mesh.triangles.size() / 8 + 1024)
        mesh.removeUnreferencedVertices();
}

} // namespace detail

} // namespace rubble
