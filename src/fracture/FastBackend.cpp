// Boolean backend on Rubble's convex-cell clipper (ConvexCellClipper): all cells that reach the mesh are cut
// in one pass as a complex (adjacent shatter cells share faces exactly), touching only the triangles near
// them. When the clipper declines a near-degenerate configuration, the whole split is redone by the exact
// Corefine backend.

#include "BooleanBackends.hpp"
#include "ConvexCellClipper.hpp"

namespace rubble::detail {

namespace {

class FastBackend final : public EditingBackend {
public:
    FastBackend(bool exactFallback, const VolumeIntegrals* inputIntegrals)
        : exactFallback_(exactFallback), inputIntegrals_(inputIntegrals) {}

    std::string name() const override { return "fast"; }

    Result<SplitResult> split(const Mesh& mesh, const std::vector<ConvexPolytope>& cells) const override {
        SplitResult out;
        out.inside.resize(cells.size());
        // Only the cells that can reach the mesh take part (the others get nothing).
        std::vector<ConvexPolytope> used;
        std::vector<std::size_t> index;
        const Aabb box = mesh.bounds();
        for (std::size_t i = 0; i < cells.size(); ++i)
            if (!cells[i].empty() && !mesh.empty() && cells[i].bounds().overlaps(box)) {
                used.push_back(cells[i]);
                index.push_back(i);
            }
        if (used.empty()) {
            out.remainder = mesh;
            if (inputIntegrals_)
                out.remainderIntegrals = *inputIntegrals_;
        } else {
            auto r = clipByConvexCells(mesh, used, inputIntegrals_);
            if (!r) {
                if (!exactFallback_)
                    return r.error();
                auto exact = makeCorefineBackend()->split(mesh, cells);
                if (!exact)
                    return makeError(exact.error().code,
                                     r.error().message + "; the exact redo failed: " + exact.error().message);
                exact->exactFallback = true;
                return exact;
            }
            for (std::size_t k = 0; k < index.size(); ++k)
                out.inside[index[k]] = std::move(r->inside[k]);
            out.remainder = std::move(r->outside);
            out.remainderIntegrals = r->outsideIntegrals;
        }
        // The clipper always emits uvs and materials; keep the layout identical when nothing is cut.
        if (out.remainder.uvs.empty())
            out.remainder.uvs.assign(3 * out.remainder.triangles.size(), Vec2f{});
        if (out.remainder.materials.empty())
            out.remainder.materials.assign(out.remainder.triangles.size(), 0u);
        return out;
    }

    Result<SplitEdit> splitAsEdit(const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                                  const Aabb& bounds) const override {
        if (!inputIntegrals_)
            return makeError(ErrorCode::InvalidInput, "fast: an edit needs the input's integrals");
        SplitEdit out;
        out.inside.resize(cells.size());
        out.insideKept.assign(cells.size(), 0);
        std::vector<ConvexPolytope> used;
        std::vector<std::size_t> index;
        for (std::size_t i = 0; i < cells.size(); ++i)
            if (!cells[i].empty() && !mesh.empty() && cells[i].bounds().overlaps(bounds)) {
                used.push_back(cells[i]);
                index.push_back(i);
            }
        if (used.empty()) {
            out.remainderIntegrals = *inputIntegrals_;
            return out;
        }
        auto r = clipByConvexCellsAsEdit(mesh, used, *inputIntegrals_);
        if (!r)
            return r.error();
        for (std::size_t k = 0; k < index.size(); ++k) {
            out.inside[index[k]] = std::move(r->inside[k]);
            out.insideKept[index[k]] = r->insideKept[k];
        }
        out.remainder = std::move(r->outside);
        out.remainderIntegrals = r->outsideIntegrals;
        return out;
    }

private:
    bool exactFallback_;
    const VolumeIntegrals* inputIntegrals_;
};

} // namespace

std::unique_ptr<BooleanBackend> makeFastBackend(bool exactFallback, const VolumeIntegrals* inputIntegrals) {
    return std::make_unique<FastBackend>(exactFallback, inputIntegrals);
}

} // namespace rubble::detail
