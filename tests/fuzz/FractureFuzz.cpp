// Fuzz target: rubble::fracture on small fuzzer-chosen meshes (valid shapes, perturbed boxes and tetrahedra,
// an L shape, random soups, shapes broken on purpose) with a fuzzer-chosen impact, impulse, seed, pattern and
// backend. fracture must never crash or throw; a broken input must be an InvalidInput error; a success must
// give closed, oriented pieces of positive volume whose volumes (plus the dropped volume) sum to the input's
// within 1e-6 relative, and the same seed must give the same pieces.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>

#include "FuzzChecks.hpp"
#include "FuzzInput.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"

namespace {

using namespace rubble;

[[noreturn]] void fail(const char* what) {
    std::fprintf(stderr, "FractureFuzz: %s\n", what);
    __builtin_trap();
}

Mesh tetrahedron() {
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    return m;
}

// The base shape, then fuzzer-driven vertex perturbations and (rarely) deliberate damage.
Mesh makeInput(fuzz::FuzzInput& in) {
    Mesh mesh;
    switch (in.byte() % 10) {
    case 0:
        mesh = makeBox({-1, -1, -1}, {1, 1, 1});
        break;
    case 1:
        mesh = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 1 + in.byte() % 3);
        break;
    case 2:
        mesh = tetrahedron();
        break;
    case 3: { // (reads sequenced left to right: function arguments are not, and gcc and clang differ)
        const int segments = 4 + in.byte() % 9;
        const int rings = 3 + in.byte() % 6;
        mesh = makeSphere({0, 0, 0}, 1.0, segments, rings);
        break;
    }
    case 4: {
        const double tube = 0.1 + (in.byte() % 8) / 10.0;
        const int segments = 4 + in.byte() % 9;
        const int rings = 3 + in.byte() % 6;
        mesh = makeTorus({0, 0, 0}, 1.0, tube, segments, rings);
        break;
    }
    case 5: { // two separate (or overlapping) parts
        mesh = makeBox({-1, -1, -1}, {0, 1, 1});
        const double dx = in.coordinate();
        mesh.append(makeBox({dx, -1, -1}, {dx + 1, 1, 1}));
        break;
    }
    case 6: { // thin plate
        const double below = 1.0 / (1 + in.byte());
        const double above = 1.0 / (1 + in.byte());
        mesh = makeSubdividedBox({-2, -below, -1}, {2, above, 1}, 1);
        break;
    }
    case 7: { // a random soup: a few vertices, a few triangles (indices may be out of range)
        const int vertices = 3 + in.byte() % 10;
        for (int i = 0; i < vertices; ++i)
            mesh.positions.push_back({in.coordinate(), in.coordinate(), in.coordinate()});
        const int triangles = 1 + in.byte() % 16;
        for (int i = 0; i < triangles; ++i)
            mesh.triangles.push_back({static_cast<std::uint32_t>(in.byte() % (vertices + 1)),
                                      static_cast<std::uint32_t>(in.byte() % (vertices + 1)),
                                      static_cast<std::uint32_t>(in.byte() % (vertices + 1))});
        return mesh;
    }
    case 9:
        mesh = fuzz::makeLShape();
        break;
    default: { // scaled, far from the origin
        const Vec3 scale{1.0 + in.byte() % 4, 1.0 / (1 + in.byte() % 8), 1.0};
        const Vec3 offset = Vec3{1e5, -2e5, 3e5} * (in.byte() % 2);
        mesh = makeBox({-1, -1, -1}, {1, 1, 1}).transformed(Mat3::identity(), scale, offset);
        break;
    }
    }
    // Perturb some vertices (a perturbed box may become concave, flat or self-intersecting).
    const int moves = in.byte() % 4;
    for (int i = 0; i < moves && !mesh.positions.empty(); ++i) {
        Vec3& p = mesh.positions[in.byte() % mesh.positions.size()];
        const Vec3 bounds = mesh.bounds().hi - mesh.bounds().lo;
        p = p +
            Vec3{in.coordinate() * bounds.x, in.coordinate() * bounds.y, in.coordinate() * bounds.z} / 4.0;
    }
    // Damage: 1 drop a triangle (open), 2 flip a triangle, 3 invert all, 4 a NaN vertex, 5 a bad index.
    const std::uint8_t damage = in.byte();
    if (damage < 250 || mesh.triangles.empty())
        return mesh;
    const std::size_t t = in.byte() % mesh.triangles.size();
    switch (damage - 250) {
    case 0:
        mesh.triangles.erase(mesh.triangles.begin() + static_cast<std::ptrdiff_t>(t));
        break;
    case 1:
        std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
        break;
    case 2:
        for (Triangle& tri : mesh.triangles)
            std::swap(tri[1], tri[2]);
        break;
    case 3:
        mesh.positions[mesh.triangles[t][0]].y = std::nan("");
        break;
    default:
        mesh.triangles[t][2] = static_cast<std::uint32_t>(mesh.positions.size() + 7);
        break;
    }
    return mesh;
}

// What fracture requires of its input, decided independently of the library's own validation.
bool acceptableInput(const Mesh& m) {
    if (m.empty())
        return false;
    for (const Triangle& t : m.triangles)
        for (std::uint32_t v : t)
            if (v >= m.positions.size())
                return false;
    for (const Vec3& p : m.positions)
        if (!isFinite(p))
            return false;
    return checkCoordinateRange(m, "fuzz").isOk() && fuzz::closedAndOriented(m) && signedVolume(m) > 0;
}

std::uint64_t hashPieces(const FractureResult& r) {
    std::uint64_t h = 1469598103934665603ull;
    for (const Piece& p : r.pieces)
        h = (h ^ p.mesh.hash()) * 1099511628211ull;
    return h;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fuzz::FuzzInput in(data, size);
    const Mesh mesh = makeInput(in);

    Impact impact;
    if (in.byte() % 4 != 0 && acceptableInput(mesh)) {
        // A point on the surface (most impacts hit): a fuzzer-chosen triangle and barycentric point.
        const auto c = mesh.corners(in.byte() % mesh.triangles.size());
        double a = in.byte() / 255.0, b = in.byte() / 255.0;
        if (a + b > 1) {
            a = 1 - a;
            b = 1 - b;
        }
        impact.point = c[0] + (c[1] - c[0]) * a + (c[2] - c[0]) * b;
    } else {
        impact.point = {in.coordinate(), in.coordinate(), in.coordinate()};
    }
    const std::uint8_t impulseByte = in.byte();
    impact.impulse = impulseByte == 0xFF ? in.rawDouble() : std::pow(10.0, impulseByte / 16.0 - 8);
    FractureParams params;
    params.pattern = in.byte() % 3 == 0 ? CellPattern::Shatter : CellPattern::SingleCell;
    params.cells = static_cast<int>(in.byte() % 10) - 1;
    params.seedPoints = static_cast<int>(in.byte() % 34) - 2;
    const double diagonal = mesh.empty() ? 1.0 : mesh.bounds().diagonal();
    params.sizeLaw.base = std::isfinite(diagonal) ? diagonal * (in.byte() + 1) / 256.0 : 1.0;
    params.sizeLaw.scale = (in.byte() % 4) * 0.05;
    const std::uint8_t backend = in.byte() % 32;
    params.backend = backend == 31 ? BooleanKind::Nef
                     : backend % 2 ? BooleanKind::Fast
                                   : BooleanKind::Corefine;
    const std::uint64_t seed = in.u64();
    const bool checkDeterminism = in.byte() % 4 == 0;

    try {
        const auto r = fracture(mesh, impact, params, seed);
        if (!acceptableInput(mesh) || !checkFractureParams(impact, params)) {
            if (r || r.error().code != ErrorCode::InvalidInput)
                fail("a broken input (mesh or impact) was not rejected as InvalidInput");
            return 0;
        }
        if (!r) {
            // A valid input may miss or defeat the kernel (it then stays whole), never be called invalid.
            const ErrorCode code = r.error().code;
            if ((code != ErrorCode::NoIntersection && code != ErrorCode::GeometryFailure) ||
                r.error().message.empty()) {
                std::fprintf(stderr, "FractureFuzz: error %d: %s\n", static_cast<int>(code),
                             r.error().message.c_str());
                fail("a valid input gave an error other than NoIntersection or GeometryFailure");
            }
            return 0;
        }
        const double v0 = signedVolume(mesh);
        double sum = r->droppedVolume;
        for (const Piece& p : r->pieces) {
            if (!(p.mass.volume > 0) || !fuzz::closedAndOriented(p.mesh) || !p.mesh.validate().isOk())
                fail("a piece is not closed, oriented and of positive volume");
            sum += p.mass.volume;
        }
        if (!(std::abs(sum - v0) <= 1e-6 * v0))
            fail("the pieces' volumes do not sum to the input's");
        if (checkDeterminism) {
            const auto again = fracture(mesh, impact, params, seed);
            if (!again || hashPieces(*again) != hashPieces(*r))
                fail("the same seed gave different pieces");
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "FractureFuzz: exception escaped: %s\n", e.what());
        __builtin_trap();
    } catch (...) {
        fail("a non-standard exception escaped");
    }
    return 0;
}
