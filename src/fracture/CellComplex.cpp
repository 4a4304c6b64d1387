#include "CellComplex.hpp"

#include <algorithm>
#include <map>
#include <string>
#include <tuple>

namespace rubble::detail {

Error clipDeclined(const char* why) {
    return Error{ErrorCode::GeometryFailure, std::string("fast clip declined: ") + why};
}

namespace {

/// The loop rotated to start at its smallest id (identifies a face whatever corner it starts from).
std::vector<std::uint32_t> canonicalLoop(std::vector<std::uint32_t> loop) {
    std::rotate(loop.begin(), std::min_element(loop.begin(), loop.end()), loop.end());
    return loop;
}

} // namespace

Result<CellComplex> buildCellComplex(const std::vector<ConvexPolytope>& polytopes, double eps) {
    CellComplex cx;
    const auto outside = static_cast<std::uint32_t>(polytopes.size());
    std::map<std::tuple<double, double, double>, std::uint32_t> index;
    std::map<std::vector<std::uint32_t>, std::uint32_t> faceByLoop;
    for (std::uint32_t c = 0; c < polytopes.size(); ++c) {
        CellComplex::Cell cell;
        cell.box = polytopes[c].bounds();
        std::unordered_map<std::uint64_t, std::uint32_t> localFaceOfEdge;
        std::vector<std::vector<std::uint32_t>> loops;
        for (const PolytopeFaceView& f : polytopes[c].faces()) {
            std::vector<std::uint32_t> loop;
            for (const Vec3& p : f.corners) {
                auto [it, inserted] = index.emplace(std::make_tuple(p.x, p.y, p.z),
                                                    static_cast<std::uint32_t>(cx.vertices.size()));
                if (inserted)
                    cx.vertices.push_back(p);
                if (loop.empty() || loop.back() != it->second)
                    loop.push_back(it->second);
            }
            while (loop.size() > 1 && loop.front() == loop.back())
                loop.pop_back();
            if (loop.size() < 3)
                continue;
            const auto local = static_cast<std::uint32_t>(loops.size());
            for (std::size_t i = 0; i < loop.size(); ++i)
                if (!localFaceOfEdge.emplace(pairKey(loop[i], loop[(i + 1) % loop.size()]), local).second)
                    return clipDeclined("cell edge used twice");
            // A face another cell already has, reversed, is shared; the same face with the same orientation
            // means the cells overlap.
            std::vector<std::uint32_t> key = canonicalLoop(loop);
            auto shared =
                faceByLoop.find(canonicalLoop(std::vector<std::uint32_t>(loop.rbegin(), loop.rend())));
            if (shared != faceByLoop.end() && cx.faces[shared->second].front == outside) {
                cx.faces[shared->second].front = c;
                cell.faces.push_back(shared->second);
                cell.flipped.push_back(true);
            } else {
                const auto id = static_cast<std::uint32_t>(cx.faces.size());
                if (!faceByLoop.emplace(std::move(key), id).second)
                    return clipDeclined("cells overlap");
                cx.faces.push_back({loop, f.plane, c, outside});
                cell.faces.push_back(id);
                cell.flipped.push_back(false);
            }
            loops.push_back(std::move(loop));
        }
        for (const auto& [key, face] : localFaceOfEdge) {
            const auto a = static_cast<std::uint32_t>(key >> 32),
                       b = static_cast<std::uint32_t>(key & 0xFFFFFFFFu);
            auto twin = localFaceOfEdge.find(pairKey(b, a));
            if (twin == localFaceOfEdge.end())
                return clipDeclined("cell is not closed");
            const std::uint32_t f = cell.faces[face], g = cell.faces[twin->second];
            cell.edgeOfFaces[pairKey(std::min(f, g), std::max(f, g))] =
                pairKey(std::min(a, b), std::max(a, b));
        }
        if (loops.size() < 4)
            return clipDeclined("cell has fewer than 4 faces");
        cx.cells.push_back(std::move(cell));
    }
    // The union's boundary (faces with the outside in front) must close up: every directed edge once and its
    // reverse once. Faces of neighbouring cells that overlap without being the same face break this.
    std::unordered_map<std::uint64_t, int> directed;
    for (const CellComplex::Face& f : cx.faces)
        if (f.front == outside)
            for (std::size_t i = 0; i < f.loop.size(); ++i)
                if (++directed[pairKey(f.loop[i], f.loop[(i + 1) % f.loop.size()])] > 1)
                    return clipDeclined("cells do not form a complex");
    for (const auto& [key, count] : directed)
        if (!directed.count(pairKey(static_cast<std::uint32_t>(key & 0xFFFFFFFFu),
                                    static_cast<std::uint32_t>(key >> 32))))
            return clipDeclined("cells do not form a complex");
    // Disjoint interiors: no pair of nearby cells overlaps by more than eps.
    for (std::uint32_t c = 0; c < polytopes.size(); ++c)
        for (std::uint32_t d = c + 1; d < polytopes.size(); ++d) {
            if (!cx.cells[c].box.overlaps(cx.cells[d].box, eps))
                continue;
            auto separates = [&](std::uint32_t a, std::uint32_t b) {
                const std::vector<Vec3> others = polytopes[b].vertices();
                for (const PolytopeFaceView& f : polytopes[a].faces())
                    if (std::all_of(others.begin(), others.end(),
                                    [&](const Vec3& p) { return f.plane.signedDistance(p) >= -eps; }))
                        return true;
                return false;
            };
            // Face planes separate most pairs; the full separating-axis test (with edge x edge axes) the
            // rest.
            if (!separates(c, d) && !separates(d, c) && withinGap(polytopes[c], polytopes[d], -eps))
                return clipDeclined("cells overlap");
        }
    return cx;
}

} // namespace rubble::detail
