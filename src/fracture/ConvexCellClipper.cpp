#include "ConvexCellClipper.hpp"

#include "Clipper.hpp"

namespace rubble::detail {

namespace clip {

Result<std::vector<Mesh>> Clipper::run(const VolumeIntegrals* known,
                                       std::optional<VolumeIntegrals>& restIntegrals, RemainderEdit* edit) {
    const std::size_t nT = mesh_.triangles.size();
    // Per vertex, the sides of the cells' box (with eps) it lies beyond, 2 bits per axis: a triangle misses
    // the box exactly when its three corners share a bit.
    thread_local std::vector<std::uint8_t> beyond;
    beyond.resize(nV_);
    const Vec3 hi{box_.hi.x + eps_, box_.hi.y + eps_, box_.hi.z + eps_}, lo = box_.lo;
    const double e = eps_;
    const Vec3* at = mesh_.positions.data();
    std::uint8_t* out = beyond.data();
    for (std::uint32_t v = 0; v < nV_; ++v) { // branch-free, so that it vectorizes
        const Vec3 p = at[v];
        out[v] = static_cast<std::uint8_t>(unsigned{p.x > hi.x} | unsigned{p.x + e < lo.x} << 1 |
                                           unsigned{p.y > hi.y} << 2 | unsigned{p.y + e < lo.y} << 3 |
                                           unsigned{p.z > hi.z} << 4 | unsigned{p.z + e < lo.z} << 5);
    }
    std::vector<std::pair<std::uint32_t, std::vector<std::uint32_t>>> cut; // triangle, cells it may cross
    std::vector<std::uint32_t> candidates;
    auto keep = [&](std::uint32_t t) { // the rest keeps t whole (an edit keeps it where it is)
        if (!edit)
            untouched_[k_].push_back(t);
    };
    for (std::uint32_t t = 0; t < nT; ++t) {
        const Triangle& tri = mesh_.triangles[t];
        if (beyond[tri[0]] & beyond[tri[1]] & beyond[tri[2]]) {
            keep(t);
            continue;
        }
        Aabb box;
        for (std::uint32_t v : tri)
            box.extend(mesh_.positions[v]);
        candidates.clear();
        std::uint32_t insideOf = kNone;
        for (std::uint32_t c = 0; c < k_; ++c) {
            if (!box.overlaps(cx_.cells[c].box, eps_))
                continue;
            for (std::uint32_t v : tri)
                ensureDistances(v);
            bool outside = false, inside = true;
            for (std::size_t l = 0; l < cx_.cells[c].faces.size() && !outside; ++l) {
                int positive = 0;
                for (std::uint32_t v : tri)
                    positive += cellDist(v, c, l) > 0;
                outside = positive == 3;
                inside &= positive == 0;
            }
            if (outside)
                continue;
            candidates.push_back(c);
            if (inside)
                insideOf = c;
        }
        if (candidates.empty())
            keep(t);
        else if (insideOf != kNone && candidates.size() == 1)
            untouched_[insideOf].push_back(t);
        else
            cut.emplace_back(t, candidates);
    }
    std::vector<std::size_t> scanned; // per region, the triangles the scan kept whole
    for (const auto& kept : untouched_)
        scanned.push_back(kept.size());
    for (const auto& [t, cells] : cut) {
        cutTriangle(t, cells);
        if (declined_)
            return clipDeclined(declined_);
    }
    buildCaps();
    if (declined_)
        return clipDeclined(declined_);

    std::vector<Mesh> result;
    for (std::uint32_t r = 0; r < k_; ++r)
        result.push_back(assemble(r));
    result.push_back(edit ? Mesh{} : assemble(k_));
    // The triangles the rest lost: those inside a cell, and those cut (a candidate the cut left whole joined
    // the untouched triangles of its region after the scan).
    std::vector<std::uint32_t> lost;
    if (known || edit) {
        std::vector<std::uint32_t> leftWhole;
        for (std::uint32_t r = 0; r <= k_; ++r)
            leftWhole.insert(leftWhole.end(), untouched_[r].begin() + static_cast<std::ptrdiff_t>(scanned[r]),
                             untouched_[r].end());
        std::sort(leftWhole.begin(), leftWhole.end());
        for (const auto& [t, cells] : cut)
            if (!std::binary_search(leftWhole.begin(), leftWhole.end(), t))
                lost.push_back(t);
        for (std::uint32_t r = 0; r < k_; ++r)
            lost.insert(lost.end(), untouched_[r].begin(), untouched_[r].end());
    }
    // The rest's integrals: the input's minus the triangles it lost plus its new ones.
    if (known) {
        VolumeIntegrals rest = *known;
        for (std::uint32_t t : lost)
            rest.remove(mesh_, t);
        for (const OutTri& o : tris_[k_])
            rest.add(pos(o.v[0]), pos(o.v[1]), pos(o.v[2]));
        restIntegrals = rest;
    }
    // Verify: the new faces close up, and no volume is created or lost.
    double sum = 0;
    for (std::uint32_t r = 0; r <= k_; ++r) {
        std::vector<std::array<std::uint32_t, 3>> created;
        created.reserve(tris_[r].size());
        for (const OutTri& o : tris_[r])
            created.push_back({o.v[0], o.v[1], o.v[2]});
        if (const char* why = openNewEdges(created, nV_))
            return clipDeclined(why);
        const bool empty = r == k_ && edit ? lost.size() == nT && tris_[k_].empty() : result[r].empty();
        const double v = empty                        ? 0.0
                         : (r == k_ && restIntegrals) ? restIntegrals->volume
                                                      : signedVolume(result[r]);
        if (v < 0)
            return clipDeclined("negative volume");
        sum += v;
    }
    const double v0 = known ? known->volume : signedVolume(mesh_);
    if (std::abs(sum - v0) > 1e-9 * std::abs(v0))
        return clipDeclined("volume not conserved");
    if (edit) {
        std::sort(lost.begin(), lost.end());
        *edit = assembleEdit(std::move(lost));
    }
    return result;
}

} // namespace clip

using clip::Clipper;

Result<CellSplit> clipByConvexCell(const Mesh& mesh, const ConvexPolytope& cell) {
    if (cell.empty())
        return makeError(ErrorCode::InvalidInput, "empty cell");
    auto split = clipByConvexCells(mesh, {cell});
    if (!split)
        return split.error();
    return CellSplit{std::move(split->outside), std::move(split->inside.front())};
}

namespace {

/// f() with a failure (e.g. out of memory) as a GeometryFailure error; empty cells are InvalidInput.
template <class F>
auto guardedClip(const std::vector<ConvexPolytope>& cells, F f) -> decltype(f()) {
    if (cells.empty() ||
        std::any_of(cells.begin(), cells.end(), [](const ConvexPolytope& c) { return c.empty(); }))
        return makeError(ErrorCode::InvalidInput, "no cells, or an empty cell");
    try {
        return f();
    } catch (const std::exception& e) {
        return makeError(ErrorCode::GeometryFailure, std::string("fast clip failed: ") + e.what());
    }
}

} // namespace

Result<MultiCellEdit> clipByConvexCellsAsEdit(const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                                              const VolumeIntegrals& meshIntegrals) {
    return guardedClip(cells, [&]() -> Result<MultiCellEdit> {
        const Clipper::Scale scale = Clipper::scaleOf(cells);
        Result<CellComplex> cx = buildCellComplex(cells, scale.eps);
        if (!cx)
            return cx.error();
        Clipper clipper(mesh, scale, std::move(*cx));
        MultiCellEdit out;
        std::optional<VolumeIntegrals> rest;
        Result<std::vector<Mesh>> run = clipper.run(&meshIntegrals, rest, &out.outside);
        if (!run)
            return run.error();
        std::vector<Mesh>& regions = *run;
        regions.pop_back();
        out.inside = std::move(regions);
        for (std::uint32_t r = 0; r < out.inside.size(); ++r)
            out.insideKept.push_back(clipper.keptWhole(r));
        out.outsideIntegrals = *rest;
        return out;
    });
}

Result<MultiCellSplit> clipByConvexCells(const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                                         const VolumeIntegrals* meshIntegrals) {
    return guardedClip(cells, [&]() -> Result<MultiCellSplit> {
        const Clipper::Scale scale = Clipper::scaleOf(cells);
        Result<CellComplex> cx = buildCellComplex(cells, scale.eps);
        if (!cx)
            return cx.error();
        Clipper clipper(mesh, scale, std::move(*cx));
        MultiCellSplit out;
        Result<std::vector<Mesh>> run = clipper.run(meshIntegrals, out.outsideIntegrals);
        if (!run)
            return run.error();
        std::vector<Mesh>& regions = *run;
        out.outside = std::move(regions.back());
        regions.pop_back();
        out.inside = std::move(regions);
        return out;
    });
}

} // namespace rubble::detail
