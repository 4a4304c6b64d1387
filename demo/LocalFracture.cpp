#include "LocalFracture.hpp"

#include <chrono>
#include <cmath>

#include "fracture/ConvexCellClipper.hpp"
#include "rubble/ConvexPolytope.hpp"
#include "rubble/Islands.hpp"
#include "rubble/MassProperties.hpp"

namespace demo {

namespace {

struct Lcg {
    std::uint64_t s;
    double next() {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<double>((s >> 11) & ((1ull << 53) - 1)) / static_cast<double>(1ull << 53);
    }
    rubble::Vec3 dir() {
        for (;;) {
            rubble::Vec3 v{next() * 2 - 1, next() * 2 - 1, next() * 2 - 1};
            const double l = rubble::length(v);
            if (l > 0.1 && l <= 1)
                return v / l;
        }
    }
};

/// Box-projected UVs for cut faces (kInteriorMaterial), 1 repeat per 3 m.
void interiorUvs(rubble::Mesh& m) {
    if (m.uvs.size() != m.triangles.size() * 3)
        m.uvs.assign(m.triangles.size() * 3, {});
    for (size_t t = 0; t < m.triangles.size(); ++t) {
        if (m.material(t) != rubble::kInteriorMaterial)
            continue;
        const rubble::Vec3 n = m.triangleNormal(t);
        const double ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
        for (int c = 0; c < 3; ++c) {
            const rubble::Vec3& p = m.positions[m.triangles[t][static_cast<size_t>(c)]];
            rubble::Vec2 uv = ax >= ay && ax >= az ? rubble::Vec2{p.z, p.y}
                              : ay >= az           ? rubble::Vec2{p.x, p.z}
                                                   : rubble::Vec2{p.x, p.y};
            m.uvs[3 * t + static_cast<size_t>(c)] = {uv.x / 3.0, uv.y / 3.0};
        }
    }
}

/// Splits a closed mesh by a plane (as a huge convex half-space cell); failure → the mesh unchanged.
std::vector<rubble::Mesh> splitByPlane(const rubble::Mesh& m, const rubble::Plane& plane) {
    rubble::Aabb box = m.bounds();
    const rubble::Vec3 pad{1, 1, 1};
    box.lo -= pad + box.size();
    box.hi += pad + box.size();
    const rubble::ConvexPolytope half = rubble::ConvexPolytope::fromAabb(box).clipped(plane, 0);
    if (half.empty())
        return {m};
    auto r = rubble::detail::clipByConvexCell(m, half);
    if (!r || r->inside.empty() || r->outside.empty())
        return {m};
    return {r->inside, r->outside};
}

void addPieces(const rubble::Mesh& m, bool debris, std::vector<LocalPiece>& out) {
    for (auto& island : rubble::splitIntoIslands(m)) {
        const rubble::MassProperties mp = rubble::computeMassProperties(island);
        if (!(mp.volume > 1e-6))
            continue;
        LocalPiece p;
        p.mesh = island.translated(rubble::Vec3{} - mp.centerOfMass);
        interiorUvs(p.mesh);
        p.offset = mp.centerOfMass;
        p.volume = mp.volume;
        p.inertia = {mp.inertia.m[0][0], mp.inertia.m[1][1], mp.inertia.m[2][2]};
        p.debris = debris;
        out.push_back(std::move(p));
    }
}

} // namespace

LocalFractureResult LocalFracture::run(std::uint32_t key, rubble::Mesh mesh, rubble::Vec3 point,
                                       rubble::Vec3 normal, double cellSize, std::uint64_t seed) {
    const auto t0 = std::chrono::steady_clock::now();
    LocalFractureResult res;
    res.key = key;
    Lcg rng{seed * 0x9E3779B97F4A7C15ull + 12345};
    const double h = cellSize * 0.5;
    const rubble::Vec3 n = rubble::normalized(normal);
    const rubble::Vec3 c = point - n * (h * 0.35);
    rubble::ConvexPolytope cell =
        rubble::ConvexPolytope::fromAabb({c - rubble::Vec3{h, h, h}, c + rubble::Vec3{h, h, h}});
    for (int k = 0; k < 9; ++k) {
        const rubble::Vec3 u = rng.dir();
        const double d = h * (0.45 + 0.4 * rng.next());
        const rubble::ConvexPolytope next = cell.clipped(rubble::Plane::fromPointNormal(c + u * d, u), k + 1);
        if (!next.empty())
            cell = next;
    }
    auto split = rubble::detail::clipByConvexCell(mesh, cell);
    if (split && !split->inside.empty()) {
        addPieces(split->outside, false, res.pieces);
        // The cut chunk crumbles: two random planes through its middle.
        std::vector<rubble::Mesh> chunks{split->inside};
        for (int k = 0; k < 2; ++k) {
            std::vector<rubble::Mesh> next;
            for (const auto& ch : chunks) {
                const rubble::Vec3 mid = rubble::computeMassProperties(ch).centerOfMass;
                const rubble::Vec3 u = rng.dir();
                for (auto& part : splitByPlane(ch, rubble::Plane::fromPointNormal(mid, u)))
                    next.push_back(std::move(part));
            }
            chunks.swap(next);
        }
        for (const auto& ch : chunks)
            addPieces(ch, true, res.pieces);
    }
    res.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return res;
}

void LocalFracture::submit(std::uint32_t key, const rubble::Mesh& mesh, const rubble::Vec3& point,
                           const rubble::Vec3& normal, double cellSize, std::uint64_t seed,
                           std::uint64_t frame) {
    jobs_.push_back(
        {key, frame,
         std::async(std::launch::async, &LocalFracture::run, key, mesh, point, normal, cellSize, seed),
         std::chrono::steady_clock::now()});
}

bool LocalFracture::busy(std::uint32_t key) const {
    for (const auto& j : jobs_)
        if (j.key == key)
            return true;
    return false;
}

std::vector<LocalFractureResult> LocalFracture::collect(std::uint64_t frame) {
    std::vector<LocalFractureResult> out;
    for (size_t i = 0; i < jobs_.size();) {
        Job& j = jobs_[i];
        const bool due = deterministic
                             ? frame >= j.frame + static_cast<std::uint64_t>(delayFrames)
                             : j.future.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
        if (due) {
            out.push_back(j.future.get());
            out.back().frame = j.frame;
            out.back().latencyMs =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - j.submitted)
                    .count();
            jobs_.erase(jobs_.begin() + static_cast<long>(i));
        } else {
            ++i;
        }
    }
    return out;
}

} // namespace demo
