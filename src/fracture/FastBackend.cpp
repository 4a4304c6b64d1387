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
        Mesh rem = mesh;
        // The clipper always emits uvs and materials; keep the layout identical when nothing is cut.
        if (rem.uvs.empty())
            rem.uvs.assign(3 * rem.triangles.size(), Vec2{});
        if (rem.materials.empty())
            rem.materials.assign(rem.triangles.size(), 0u);
        for (std::size_t i = 0; i < cells.size(); ++i) {
            if (cells[i].empty() || rem.empty() || !cells[i].bounds().overlaps(rem.bounds()))
                continue;
            auto r = clipByConvexCell(rem, cells[i]);
            if (!r)
                return makeCorefineBackend()->split(mesh, cells);
            out.inside[i] = std::move(r->inside);
            rem = std::move(r->outside);
        }
        out.remainder = std::move(rem);
        return out;
    }
};

} // namespace

std::unique_ptr<BooleanBackend> makeFastBackend() {
    return std::make_unique<FastBackend>();
}

} // namespace rubble::detail
