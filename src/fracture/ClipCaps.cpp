#include "Clipper.hpp"

#include "geometry/RayParity.hpp"

namespace rubble::detail::clip {

bool Clipper::pointInsideMesh(const Vec3& p) const {
    // All triangle indices; not std::views::iota, which clang 14 cannot compile with libstdc++ 12 (the
    // sanitizer and fuzzer builds use clang).
    struct AllTriangles {
        struct It {
            std::size_t i;
            std::size_t operator*() const { return i; }
            It& operator++() {
                ++i;
                return *this;
            }
            bool operator!=(const It& o) const { return i != o.i; }
        };
        std::size_t n;
        It begin() const { return {0}; }
        It end() const { return {n}; }
    };
    return insideByRayParity(mesh_, AllTriangles{mesh_.triangles.size()}, p);
}

void Clipper::buildCaps() {
    // Map: per face, point -> whether the back cell's polygon cut edge leaves it (true) or arrives at it
    // (false).
    std::vector<std::unordered_map<std::uint32_t, bool>> leaves(nF_);
    for (std::uint32_t f = 0; f < nF_; ++f)
        for (const auto& [a, b] : cutEdges_[f]) {
            leaves[f][b] = true;
            leaves[f][a] = false;
        }
    for (auto& [edge, points] : pierce_) { // every cell around a complex edge reports its pierce points
        std::sort(points.begin(), points.end());
        points.erase(std::unique(points.begin(), points.end()), points.end());
    }
    const std::size_t nCellVerts = cx_.vertices.size();
    std::vector<int> vertexInside(nCellVerts, -1);
    auto setStatus = [&](std::uint32_t v, int s) {
        if (vertexInside[v] >= 0 && vertexInside[v] != s) {
            decline("inconsistent cell vertex status");
            return false;
        }
        vertexInside[v] = s;
        return true;
    };
    // Per directed edge of face f: sorted pierce points and the inside status of each sub-edge.
    struct EdgeSplit {
        std::vector<std::uint32_t> points;
        std::vector<int> inside; // points.size() + 1 entries
    };
    std::vector<std::vector<EdgeSplit>> splits(nF_);
    for (std::uint32_t f = 0; f < nF_; ++f) {
        const auto& loop = cx_.faces[f].loop;
        splits[f].resize(loop.size());
        for (std::size_t e = 0; e < loop.size(); ++e) {
            const std::uint32_t A = loop[e], B = loop[(e + 1) % loop.size()];
            EdgeSplit& s = splits[f][e];
            if (auto it = pierce_.find(pairKey(std::min(A, B), std::max(A, B))); it != pierce_.end())
                s.points = it->second;
            const Vec3 pa = cx_.vertices[A], dir = cx_.vertices[B] - pa;
            std::sort(s.points.begin(), s.points.end(), [&](std::uint32_t x, std::uint32_t y) {
                return dot(pos(x) - pa, dir) < dot(pos(y) - pa, dir);
            });
            s.inside.assign(s.points.size() + 1, -1);
            for (std::size_t q = 0; q < s.points.size(); ++q) {
                auto it = leaves[f].find(s.points[q]);
                if (it == leaves[f].end()) {
                    decline("pierce point without cut edge");
                    return;
                }
                const int before =
                    it->second ? 1 : 0; // cap edge leaves the point: the sub-edge before is inside
                for (auto [slot, value] : {std::pair{q, before}, std::pair{q + 1, 1 - before}}) {
                    if (s.inside[slot] >= 0 && s.inside[slot] != value) {
                        decline("inconsistent cut along a cell edge");
                        return;
                    }
                    s.inside[slot] = value;
                }
            }
            if (!s.points.empty() && (!setStatus(A, s.inside.front()) || !setStatus(B, s.inside.back())))
                return;
        }
    }
    // Propagate vertex status along unpierced complex edges; with no information at all, cast a ray.
    bool changed = true;
    while (changed) {
        changed = false;
        for (std::uint32_t f = 0; f < nF_; ++f) {
            const auto& loop = cx_.faces[f].loop;
            for (std::size_t e = 0; e < loop.size(); ++e) {
                if (!splits[f][e].points.empty())
                    continue;
                const std::uint32_t A = loop[e], B = loop[(e + 1) % loop.size()];
                if (vertexInside[A] >= 0 && vertexInside[B] < 0) {
                    vertexInside[B] = vertexInside[A];
                    changed = true;
                } else if (vertexInside[B] >= 0 && vertexInside[A] < 0) {
                    vertexInside[A] = vertexInside[B];
                    changed = true;
                } else if (vertexInside[A] >= 0 && vertexInside[A] != vertexInside[B]) {
                    decline("inconsistent unpierced cell edge");
                    return;
                }
            }
        }
        if (!changed && std::find(vertexInside.begin(), vertexInside.end(), -1) != vertexInside.end()) {
            const auto it = std::find(vertexInside.begin(), vertexInside.end(), -1);
            *it = pointInsideMesh(cx_.vertices[static_cast<std::size_t>(it - vertexInside.begin())]) ? 1 : 0;
            changed = true;
        }
    }
    // Complex vertices become points (created lazily when a cap uses them). A cap goes to the face's back
    // cell as it is and to the region in front reversed.
    auto cellPoint = [&](std::uint32_t v) { return addPoint({3, v, 0, 0}, cx_.vertices[v]); };
    std::vector<OutTri> caps;
    for (std::uint32_t f = 0; f < nF_; ++f) {
        std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
        for (const auto& [a, b] : cutEdges_[f])
            edges.emplace_back(b, a);
        const auto& loop = cx_.faces[f].loop;
        for (std::size_t e = 0; e < loop.size(); ++e) {
            const std::uint32_t A = loop[e], B = loop[(e + 1) % loop.size()];
            const EdgeSplit& s = splits[f][e];
            if (s.points.empty()) {
                if (vertexInside[A] == 1)
                    edges.emplace_back(cellPoint(A), cellPoint(B));
                continue;
            }
            for (std::size_t q = 0; q <= s.points.size(); ++q) {
                if (s.inside[q] != 1)
                    continue;
                const std::uint32_t from = q == 0 ? cellPoint(A) : s.points[q - 1];
                const std::uint32_t to = q == s.points.size() ? cellPoint(B) : s.points[q];
                edges.emplace_back(from, to);
            }
        }
        if (edges.empty())
            continue;
        caps.clear();
        triangulateRegion(edges, edges.size(), cx_.faces[f].plane.normal, kNone, f, caps);
        if (declined_)
            return;
        for (const OutTri& c : caps) {
            tris_[cx_.faces[f].back].push_back(c);
            tris_[cx_.faces[f].front].push_back({{c.v[0], c.v[2], c.v[1]}, kNone, f, true});
        }
    }
}

} // namespace rubble::detail::clip
