// Boolean backend on Rubble's convex-cell clipper (ConvexCellClipper): cells are cut one after the other
// from the remainder, touching only the triangles near each cell. When the clipper declines a
// near-degenerate configuration, the whole split is redone by the exact Corefine backend.

#include "BooleanBackends.hpp"
#include "ConvexCellClipper.hpp"

namespace rubble::detail {

namespace {

class FastBackend final : public BooleanBackend {
public:
    std::string name() const override { return "fast"; }

    Result<SplitResult> split(const Mesh& mesh, const std::vector<ConvexPolytope>& cells) const override {
        SplitResult out;
        out.inside.resize(cells.size());
        // The remainder is the input until the first cell cuts it (no copy of the whole mesh up front).
        const Mesh* rem = &mesh;
        Mesh cut;
        for (std::size_t i = 0; i < cells.size(); ++i) {
            if (cells[i].empty() || rem->empty() || !cells[i].bounds().overlaps(rem->bounds()))
                continue;
            auto r = clipByConvexCell(*rem, cells[i]);
            if (!r) {
                auto exact = makeCorefineBackend()->split(mesh, cells);
                if (exact)
                    exact->exactFallback = true;
                return exact;
            }
            out.inside[i] = std::move(r->inside);
            cut = std::move(r->outside);
            rem = &cut;
        }
        out.remainder = rem == &mesh ? mesh : std::move(cut);
        // The clipper always emits uvs and materials; keep the layout identical when nothing is cut.
        if (out.remainder.uvs.empty())
            out.remainder.uvs.assign(3 * out.remainder.triangles.size(), Vec2{});
        if (out.remainder.materials.empty())
            out.remainder.materials.assign(out.remainder.triangles.size(), 0u);
        return out;
    }
};

} // namespace

std::unique_ptr<BooleanBackend> makeFastBackend() {
    return std::make_unique<FastBackend>();
}

} // namespace rubble::detail
