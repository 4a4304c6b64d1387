// Fuzz target: the fast convex-cell clipper on generated closed shapes with fuzzer-chosen cells, including
// degenerate ones (planes through vertices, axis-aligned faces, tiny and huge cells). Whenever the clipper
// accepts a configuration, both outputs must be closed, consistently oriented and conserve volume.
#include <cstdint>

#include "FuzzChecks.hpp"
#include "FuzzInput.hpp"
#include "fracture/ConvexCellClipper.hpp"
#include "rubble/geometry/MassProperties.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace rubble;
    fuzz::FuzzInput in(data, size);
    Mesh mesh;
    switch (in.byte() % 5) {
    case 0:
        mesh = makeBox({-1, -1, -1}, {1, 1, 1});
        break;
    case 1:
        mesh = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 1 + in.byte() % 4);
        break;
    case 2: { // (reads sequenced left to right: function arguments are not, and gcc and clang differ)
        const int segments = 6 + in.byte() % 10;
        const int rings = 4 + in.byte() % 6;
        mesh = makeSphere({0, 0, 0}, 1.0, segments, rings);
        break;
    }
    case 3: {
        const int segments = 6 + in.byte() % 10;
        const int rings = 4 + in.byte() % 6;
        mesh = makeTorus({0, 0, 0}, 1.0, 0.4, segments, rings);
        break;
    }
    default:
        mesh = makeBox({-2, -0.125, -1}, {2, 0.125, 1});
        break;
    }
    const Vec3 c{in.coordinate(), in.coordinate(), in.coordinate()};
    const double r = 0.05 + (in.byte() % 64) / 16.0;
    if (!isFinite(c))
        return 0;
    ConvexPolytope cell = ConvexPolytope::fromAabb({c - Vec3{r, r, r}, c + Vec3{r, r, r}});
    const int planes = in.byte() % 16;
    for (int i = 0; i < planes; ++i) {
        const Vec3 n = normalized(Vec3{in.coordinate(), in.coordinate(), in.coordinate()});
        if (!isFinite(n) || length(n) < 0.5)
            continue;
        const ConvexPolytope q =
            cell.clipped(Plane::fromPointNormal(c + n * (r * (in.byte() % 17) / 16.0), n), i);
        if (!q.empty())
            cell = q;
    }
    auto split = detail::clipByConvexCell(mesh, cell);
    if (!split)
        return 0; // declined: the exact backend handles it
    const double v = signedVolume(mesh);
    const double vi = split->inside.empty() ? 0.0 : signedVolume(split->inside);
    const double vo = split->outside.empty() ? 0.0 : signedVolume(split->outside);
    if (std::abs(vi + vo - v) > 1e-9 * v || vi < 0 || vo < 0)
        __builtin_trap();
    if (!fuzz::closedAndOriented(split->inside) || !fuzz::closedAndOriented(split->outside))
        __builtin_trap();
    return 0;
}
