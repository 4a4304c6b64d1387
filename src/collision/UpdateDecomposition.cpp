// Incremental update of a decomposition at fracture time (Mueller et al. 2013): the parent's convex parts are
// clipped by the cells' planes, and every fragment goes to the piece that contains it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <unordered_map>

#include "collision/HullWitness.hpp"
#include "collision/MeshRegion.hpp"
#include "collision/SmallHull.hpp"
#include "rubble/collision/CollisionTolerance.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"

namespace rubble {

namespace {

/// Of a high-poly remainder over the budget, dented parts are made whole again while this adds at most this
/// fraction of its parts' volume; a high-poly piece's parts become their hull when it is at most this much
/// larger than their sum (docs/megamesh.md).
constexpr double kHighPolyFillTolerance = 0.01;

/// The share of kPartOverlapTolerance that the merges of a remainder may spend (the rest is margin for the
/// pieces' real surfaces against the cells).
constexpr double kOverlapShare = 0.5;

struct Fragment {
    ConvexPolytope shape;
    std::int32_t cell = -1; // -1: outside every cell
    std::uint32_t part = 0; // index of the parent part it was cut from
};

/// Whether some corner of p lies inside (below) and some outside (above) plane, beyond the tolerance of
/// ConvexPolytope::clipped: a plane with nothing above it leaves p as it is, without a copy.
struct Sides {
    bool in = false, out = false;
};
Sides sidesOf(const ConvexPolytope& p, const Plane& plane) {
    const Aabb b = p.bounds();
    const double tol =
        1e-12 * std::max(1.0, std::max({std::abs(b.lo.x), std::abs(b.lo.y), std::abs(b.lo.z),
                                        std::abs(b.hi.x), std::abs(b.hi.y), std::abs(b.hi.z)}));
    Sides s;
    for (const PolytopeFaceView& f : p.faces())
        for (const Vec3& c : f.corners) {
            const double d = plane.signedDistance(c);
            s.out |= d > tol;
            s.in |= d < -tol;
        }
    return s;
}

/// part ∩ cell, or empty; clips only by the planes that cut it.
ConvexPolytope intersectCell(const ConvexPolytope& part, const ConvexPolytope& cell) {
    ConvexPolytope inside;
    const ConvexPolytope* current = &part;
    for (const PolytopeFaceView& f : cell.faces()) {
        const Sides s = sidesOf(*current, f.plane);
        if (!s.out)
            continue;
        if (!s.in)
            return {};
        inside = current->clipped(f.plane);
        current = &inside;
        if (inside.empty())
            return {};
    }
    return current == &part ? part : inside;
}

/// part − cell as at most one fragment per cell plane: outside plane j and inside planes < j.
void subtractCell(const ConvexPolytope& part, const ConvexPolytope& cell, std::vector<ConvexPolytope>& out) {
    ConvexPolytope rest = part;
    for (const PolytopeFaceView& f : cell.faces()) {
        const Sides s = sidesOf(rest, f.plane);
        if (!s.out) { // nothing outside this plane: rest unchanged (a flat rest on the plane is both)
            if (!s.in)
                out.push_back(rest);
            continue;
        }
        if (!s.in) { // all of rest outside
            out.push_back(std::move(rest));
            return;
        }
        if (ConvexPolytope outside = rest.clippedOutside(f.plane); !outside.empty())
            out.push_back(std::move(outside));
        rest = rest.clipped(f.plane);
        if (rest.empty())
            return;
    }
}

/// A face of a cell that no other cell shares: a piece of the boundary of the cells' union.
struct OuterFace {
    Plane plane; // outward from its cell
    std::size_t cell = 0;
    double area = 0;
    Aabb bounds;
};

/// The outer faces of the cells, largest first (a face whose plane another touching cell has, reversed, is
/// shared and lies inside the union).
std::vector<OuterFace> outerFaces(const std::vector<ConvexPolytope>& cells,
                                  const std::vector<Aabb>& cellBounds) {
    std::vector<OuterFace> out;
    for (std::size_t c = 0; c < cells.size(); ++c) {
        const double tol = 1e-9 * (cellBounds[c].diagonal() + 1);
        for (const PolytopeFaceView& f : cells[c].faces()) {
            bool shared = false;
            for (std::size_t d = 0; d < cells.size() && !shared; ++d) {
                if (d == c || !cellBounds[d].overlaps(cellBounds[c], tol))
                    continue;
                for (const PolytopeFaceView& g : cells[d].faces())
                    if (dot(f.plane.normal, g.plane.normal) < -1 + 1e-9 &&
                        std::abs(f.plane.offset + g.plane.offset) < tol) {
                        shared = true;
                        break;
                    }
            }
            if (shared)
                continue;
            OuterFace o{f.plane, c, 0, {}};
            for (std::size_t k = 1; k + 1 < f.corners.size(); ++k)
                o.area += 0.5 * length(cross(f.corners[k] - f.corners[0], f.corners[k + 1] - f.corners[0]));
            for (const Vec3& p : f.corners)
                o.bounds.extend(p);
            out.push_back(std::move(o));
        }
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const OuterFace& a, const OuterFace& b) { return a.area > b.area; });
    return out;
}

/// region − every cell by sequential subtraction (fragments along every cell plane, shared ones included).
void subtractSequentially(const ConvexPolytope& region, const std::vector<ConvexPolytope>& cells,
                          const std::vector<Aabb>& cellBounds, std::vector<ConvexPolytope>& out) {
    const Aabb pb = region.bounds();
    std::vector<ConvexPolytope> rest{region}, next;
    std::vector<Aabb> restBounds{pb}, nextBounds;
    for (std::size_t c = 0; c < cells.size(); ++c) {
        if (!pb.overlaps(cellBounds[c]))
            continue;
        next.clear();
        nextBounds.clear();
        for (std::size_t r = 0; r < rest.size(); ++r) {
            if (!restBounds[r].overlaps(
                    cellBounds[c])) { // a fragment away from the cell is moved on untouched
                next.push_back(std::move(rest[r]));
                nextBounds.push_back(restBounds[r]);
                continue;
            }
            const std::size_t first = next.size();
            subtractCell(rest[r], cells[c], next);
            for (std::size_t k = first; k < next.size(); ++k)
                nextBounds.push_back(next[k].bounds());
        }
        rest.swap(next);
        restBounds.swap(nextBounds);
    }
    for (ConvexPolytope& r : rest)
        out.push_back(std::move(r));
}

/// Deepest split of subtractUnion before it subtracts cell by cell.
constexpr int kMaxUnionSplits = 32;

/// region − ∪cells as convex fragments, split only along the outer faces of the union (largest first): a
/// region clear of the cells is kept whole, one inside them dropped. Far fewer fragments than subtracting
/// cell by cell, whose shared faces cut the remainder into slabs (docs/collision.md).
void subtractUnion(const ConvexPolytope& region, const std::vector<ConvexPolytope>& cells,
                   const std::vector<Aabb>& cellBounds, const std::vector<OuterFace>& faces, int depth,
                   std::vector<ConvexPolytope>& out) {
    const Aabb rb = region.bounds();
    const double volume = region.volume();
    double covered = 0;
    std::vector<bool> touching(cells.size(), false);
    for (std::size_t c = 0; c < cells.size(); ++c)
        if (rb.overlaps(cellBounds[c]))
            if (const double v = intersectCell(region, cells[c]).volume(); v > 0) {
                covered += v;
                touching[c] = true;
            }
    if (covered <= 1e-9 * volume) {
        out.push_back(region);
        return;
    }
    if (covered >= (1 - 1e-9) * volume)
        return;
    if (depth < kMaxUnionSplits)
        for (const OuterFace& f : faces) {
            if (!touching[f.cell] || !rb.overlaps(f.bounds))
                continue;
            const Sides s = sidesOf(region, f.plane);
            if (!s.in || !s.out)
                continue;
            if (ConvexPolytope outside = region.clippedOutside(f.plane); !outside.empty())
                subtractUnion(outside, cells, cellBounds, faces, depth + 1, out);
            if (ConvexPolytope inside = region.clipped(f.plane); !inside.empty())
                subtractUnion(inside, cells, cellBounds, faces, depth + 1, out);
            return;
        }
    subtractSequentially(region, cells, cellBounds, out);
}

/// The pyramid over a face to an apex beyond its plane.
ConvexPolytope pyramid(const PolytopeFaceView& base, const Vec3& apex) {
    std::vector<Vec3> ring(base.corners.begin(), base.corners.end());
    Vec3 mid = apex;
    for (const Vec3& q : ring)
        mid += q;
    mid = mid / static_cast<double>(ring.size() + 1);
    std::vector<PolytopeFace> faces;
    auto add = [&](std::vector<Vec3> corners) { // oriented away from the pyramid's centroid
        Vec3 n = normalized(cross(corners[1] - corners[0], corners[2] - corners[0]));
        if (dot(n, mid - corners[0]) > 0) {
            std::reverse(corners.begin(), corners.end());
            n = -n;
        }
        faces.push_back({Plane{n, dot(n, corners[0])}, std::move(corners), -1});
    };
    for (std::size_t e = 0; e < ring.size(); ++e)
        add({ring[e], ring[(e + 1) % ring.size()], apex});
    add(std::move(ring));
    return ConvexPolytope::fromFaces(std::move(faces));
}

/// Volume of a shape inside each cell it reaches: (cell index, volume).
using Overlaps = std::vector<std::pair<std::uint32_t, double>>;

/// The cells whose pieces a remainder's parts must stay out of, and the overlap each cell still allows (a
/// share of kPartOverlapTolerance; docs/collision.md). Merges and hulls that would cover a crater are
/// refused.
class CellGuard {
public:
    CellGuard(const std::vector<ConvexPolytope>& cells, const std::vector<Aabb>& bounds,
              std::vector<double> allowance)
        : cells_(cells), bounds_(bounds), left_(std::move(allowance)) {}

    Overlaps overlaps(const ConvexPolytope& shape) const {
        Overlaps out;
        const Aabb b = shape.bounds();
        for (std::size_t c = 0; c < cells_.size(); ++c) {
            if (!(left_[c] < std::numeric_limits<double>::infinity()) || !b.overlaps(bounds_[c]) ||
                separated(shape, b, cells_[c], bounds_[c]))
                continue;
            const double v = intersectCell(shape, cells_[c]).volume();
            if (v > 0)
                out.emplace_back(static_cast<std::uint32_t>(c), v);
        }
        return out;
    }
    /// How far the overlaps exceed what the cells still allow (0: they fit).
    double excess(const Overlaps& o) const { return excessAt(o, epoch()); }
    /// The same against what the cells allowed at an earlier epoch (the count of take() calls before it).
    double excessAt(const Overlaps& o, std::size_t epoch) const {
        const std::vector<double>& left = epoch < history_.size() ? history_[epoch] : left_;
        double e = 0;
        for (const auto& [c, v] : o)
            e += std::max(0.0, v - left[c]);
        return e;
    }
    std::size_t epoch() const { return history_.size(); }
    /// A lower bound of the excess of hull(a ∪ b), from a cone inside it (docs/collision.md); 0: none proven.
    double excessAtLeast(const ConvexPolytope& a, const Overlaps& ownedA, const ConvexPolytope& b,
                         const Overlaps& ownedB) const {
        Aabb joint = a.bounds();
        joint.extend(b.bounds());
        for (int side = 0; side < 2; ++side) {
            const ConvexPolytope& from = side == 0 ? a : b;
            const ConvexPolytope& to = side == 0 ? b : a;
            const Overlaps& ownedTo = side == 0 ? ownedB : ownedA;
            std::vector<std::pair<double, ConvexPolytope>> cone; // (volume, pyramid), largest first
            for (std::size_t c = 0; c < cells_.size(); ++c) {
                if (!(left_[c] < std::numeric_limits<double>::infinity()) || !joint.overlaps(bounds_[c]))
                    continue;
                if (cone.empty()) {
                    // The apex: the corner of `from` nearest to the first such cell's box centre.
                    const Vec3 g = bounds_[c].center();
                    Vec3 apex = from.corners().front();
                    for (const Vec3& p : from.corners())
                        if (lengthSquared(p - g) < lengthSquared(apex - g))
                            apex = p;
                    const double flat = 1e-9 * joint.diagonal();
                    for (const PolytopeFaceView& f : to.faces())
                        if (f.plane.signedDistance(apex) > flat) {
                            ConvexPolytope p = pyramid(f, apex);
                            const double v = p.volume();
                            cone.emplace_back(v, std::move(p));
                        }
                    if (cone.empty())
                        break;
                    std::stable_sort(cone.begin(), cone.end(),
                                     [](const auto& x, const auto& y) { return x.first > y.first; });
                }
                const double before = inCell(ownedA, c) + inCell(ownedB, c);
                double inside = inCell(ownedTo, c);
                for (const auto& [v, p] : cone) {
                    if (!p.bounds().overlaps(bounds_[c]))
                        continue;
                    inside += intersectCell(p, cells_[c]).volume();
                    // Margins for the rounding of two different clippings of the same volume.
                    if (const double e = inside - before - left_[c] * (1 + 1e-6) - 1e-9 * inside; e > 0)
                        return e;
                }
            }
        }
        return 0;
    }
    /// What a merged hull overlaps beyond what the two parts it replaces overlapped already.
    static Overlaps added(const Overlaps& merged, const Overlaps& a, const Overlaps& b) {
        Overlaps out;
        for (const auto& [c, v] : merged) {
            const double before = inCell(a, c) + inCell(b, c);
            if (v > before)
                out.emplace_back(c, v - before);
        }
        return out;
    }
    void take(const Overlaps& o) {
        history_.push_back(left_);
        for (const auto& [c, v] : o)
            left_[c] -= v;
    }

private:
    /// The overlap that o lists for cell c (0 when none).
    static double inCell(const Overlaps& o, std::size_t c) {
        double v = 0;
        for (const auto& [d, w] : o)
            v += d == c ? w : 0;
        return v;
    }
    /// True when a face plane of either polytope has the other's corners all beyond it by far more than the
    /// clipping's tolerance: their intersection is empty, without clipping.
    static bool separated(const ConvexPolytope& a, const Aabb& ab, const ConvexPolytope& b, const Aabb& bb) {
        double scale = 1;
        for (const Aabb* box : {&ab, &bb})
            for (const Vec3& p : {box->lo, box->hi})
                scale = std::max({scale, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        const double margin = 1e-6 * scale;
        auto beyond = [margin](const ConvexPolytope& planes, const ConvexPolytope& points) {
            for (const PolytopeFaceView& f : planes.faces()) {
                bool all = true;
                for (const PolytopeFaceView& g : points.faces()) {
                    for (const Vec3& p : g.corners)
                        if (!(f.plane.signedDistance(p) > margin)) {
                            all = false;
                            break;
                        }
                    if (!all)
                        break;
                }
                if (all)
                    return true;
            }
            return false;
        };
        return beyond(b, a) || beyond(a, b);
    }

    const std::vector<ConvexPolytope>& cells_;
    const std::vector<Aabb>& bounds_;
    std::vector<double> left_;
    std::vector<std::vector<double>> history_; // left_ before each take()
};

/// The points extreme in the 26 directions of a cube's faces, edges and corners (repeats removed).
std::vector<Vec3> extremePoints(const std::vector<Vec3>& pts) {
    std::vector<Vec3> out;
    for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y)
            for (int z = -1; z <= 1; ++z) {
                if (x == 0 && y == 0 && z == 0)
                    continue;
                const Vec3 d{double(x), double(y), double(z)};
                std::size_t best = 0;
                for (std::size_t i = 1; i < pts.size(); ++i)
                    if (dot(d, pts[i]) > dot(d, pts[best]))
                        best = i;
                if (!pts.empty() && std::find(out.begin(), out.end(), pts[best]) == out.end())
                    out.push_back(pts[best]);
            }
    return out;
}

/// The polytope clipped to an axis-aligned box (only by the box planes it crosses).
ConvexPolytope clippedToBox(ConvexPolytope p, const Aabb& box) {
    const Aabb b = p.bounds();
    for (int a = 0; a < 3 && !p.empty(); ++a) {
        Vec3 n;
        n[a] = 1;
        if (b.hi[a] > box.hi[a])
            p = p.clipped({n, box.hi[a]});
        if (!p.empty() && b.lo[a] < box.lo[a])
            p = p.clipped({-n, -box.lo[a]});
    }
    return p;
}

double distanceToBox(const Aabb& b, const Vec3& p) {
    const Vec3 d = max(max(b.lo - p, p - b.hi), Vec3{});
    return length(d);
}

double boxVolume(const Aabb& b) {
    const Vec3 e = max(b.size(), Vec3{});
    return e.x * e.y * e.z;
}

/// Replaces the fragments of each parent part by their joint hull (inside that convex part): one hull per
/// parent part instead of pairwise merges, for patterns that cut a part into thousands of fragments. A hull
/// that the guard refuses (it would cover a crater) leaves its fragments as they are.
void collapseSiblings(std::vector<ConvexPolytope>& parts, std::vector<std::uint32_t>& origin,
                      CellGuard* guard) {
    std::map<std::uint32_t, std::vector<std::size_t>> byOrigin;
    for (std::size_t i = 0; i < parts.size(); ++i)
        byOrigin[origin[i]].push_back(i);
    std::vector<ConvexPolytope> merged;
    std::vector<std::uint32_t> mergedOrigin;
    for (const auto& [o, members] : byOrigin) {
        if (members.size() > 1) {
            std::vector<Vec3> pts;
            for (std::size_t i : members) {
                const auto v = parts[i].vertices();
                pts.insert(pts.end(), v.begin(), v.end());
            }
            auto h = detail::hullOfFew(pts);
            const Overlaps covered = h && guard ? guard->overlaps(*h) : Overlaps{};
            if (h && (!guard || guard->excess(covered) <= 0)) {
                if (guard)
                    guard->take(covered);
                merged.push_back(std::move(h.value()));
                mergedOrigin.push_back(o);
                continue;
            }
        }
        for (std::size_t i : members) { // a single fragment, or a hull that failed: kept as they are
            merged.push_back(std::move(parts[i]));
            mergedOrigin.push_back(o);
        }
    }
    parts = std::move(merged);
    origin = std::move(mergedOrigin);
}

/// Of a high-poly remainder over the budget: the fragments of a parent part become that part whole again (no
/// hull), the least dented part first, while the volume this adds stays within tolerance of the parts' sum.
void revertToParents(std::vector<ConvexPolytope>& parts, std::vector<std::uint32_t>& origin,
                     const std::vector<ConvexPolytope>& parentParts, std::size_t budget, double tolerance,
                     const Aabb* box, CellGuard* guard) {
    struct Group {
        double volume = 0;
        std::size_t count = 0;
    };
    std::map<std::uint32_t, Group> groups;
    double sum = 0;
    for (std::size_t i = 0; i < parts.size(); ++i) {
        const double v = parts[i].volume();
        sum += v;
        groups[origin[i]].volume += v;
        ++groups[origin[i]].count;
    }
    std::vector<std::pair<double, std::uint32_t>> byDent; // (dent, origin), origins cut into several
    for (const auto& [o, g] : groups)
        if (g.count > 1)
            byDent.emplace_back(std::max(0.0, parentParts[o].volume() - g.volume), o);
    std::sort(byDent.begin(), byDent.end());
    std::vector<bool> whole(parentParts.size(), false);
    std::size_t count = parts.size();
    double added = 0;
    for (const auto& [dent, o] : byDent) {
        if (count <= budget || added + dent > tolerance * sum)
            break;
        if (guard) { // a whole part would cover the crater its fragments leave open
            const Overlaps ov = guard->overlaps(parentParts[o]);
            if (guard->excess(ov) > 0)
                continue;
            guard->take(ov);
        }
        whole[o] = true;
        added += dent;
        count -= groups[o].count - 1;
    }
    if (count == parts.size())
        return;
    std::vector<ConvexPolytope> kept;
    std::vector<std::uint32_t> keptOrigin;
    for (std::size_t i = 0; i < parts.size(); ++i) {
        if (!whole[origin[i]]) {
            kept.push_back(std::move(parts[i]));
            keptOrigin.push_back(origin[i]);
        } else if (std::find(keptOrigin.begin(), keptOrigin.end(), origin[i]) == keptOrigin.end()) {
            ConvexPolytope part = box ? clippedToBox(parentParts[origin[i]], *box) : parentParts[origin[i]];
            if (!part.empty()) {
                kept.push_back(std::move(part));
                keptOrigin.push_back(origin[i]);
            }
        }
    }
    parts = std::move(kept);
    origin = std::move(keptOrigin);
}

/// Merges touching parts until at most maxParts remain, preferring the pairs whose joint hull adds the least
/// volume. Pairs are ranked by a cheap estimate, the volume their joint bounding box adds to the union of
/// their two boxes (no hull per pair: the ranking was a Qhull call per touching pair, quadratic in the part
/// count); the two best-ranked pairs are then compared by their true joint hull, and the winner's hull is the
/// merged part. Hulls of the losers are kept for the next round (keyed by the pair's versions). Siblings
/// (fragments of the same parent part, origin[i] == origin[j]) are merged first: they tile their parent part
/// minus the cells, so their joint hull stays inside that convex part. Only when that does not reach the
/// budget are all touching pairs considered. With a guard, a merge whose hull would cover a crater beyond
/// what the guard allows is ranked behind every other (by that excess) and taken only when nothing else is
/// left.
void mergeToBudget(std::vector<ConvexPolytope>& parts, std::vector<std::uint32_t> origin, int maxParts,
                   CellGuard* guard) {
    const std::size_t budget = static_cast<std::size_t>(std::max(1, maxParts));
    // A guarded piece stops merging at up to kCraterBudgetFactor times the budget rather than cover a crater.
    std::size_t stretch = guard ? budget * kCraterBudgetFactor : budget;
    if (parts.size() <= budget)
        return;
    if (parts.size() > 4 * budget) // pairwise merging is quadratic in the fragment count
        collapseSiblings(parts, origin, guard);
    // Too many fragments to keep the craters open within the budget: collapsed as they were
    // (docs/collision.md).
    if (guard && parts.size() > 4 * stretch) {
        guard = nullptr;
        stretch = budget;
        collapseSiblings(parts, origin, nullptr);
    }
    if (parts.size() <= budget)
        return;
    struct Candidate {
        double cost;
        std::size_t i, j;
        std::uint32_t vi, vj;   // versions of i and j when ranked
        bool covers = false;    // its hull covers a crater beyond the guard's allowance; cost is that excess
        bool estimated = false; // covers by a lower bound: cost is a lower bound, its hull not yet computed
        std::size_t epoch = 0;  // the guard's epoch when it was refused
        bool operator>(const Candidate& o) const { return covers != o.covers ? covers : cost > o.cost; }
    };
    struct Hull {
        std::uint32_t vi, vj;
        double cost;
        ConvexPolytope shape;
        Overlaps overlaps; // with the guard's cells
        Overlaps added;    // of which the two parts did not overlap already
    };
    const std::size_t n = parts.size();
    std::vector<std::uint32_t> version(n, 0);
    std::vector<bool> alive(n, true);
    std::vector<Aabb> bounds(n);
    std::vector<double> volumes(n);
    std::vector<std::vector<Vec3>> corners(n); // welded when a joint hull first needs them
    std::vector<Overlaps> owned(n); // each merged part's overlap with the guard's cells (fragments have none)
    std::vector<std::vector<std::size_t>> blocked(n); // partners whose joint hull covers a crater
    for (std::size_t i = 0; i < n; ++i) {
        bounds[i] = parts[i].bounds();
        volumes[i] = parts[i].volume();
    }
    // Many fragments (a shatter pattern cuts each part into hundreds): the box ranking alone decides.
    const std::size_t verified = n > 2 * budget ? 1 : 2;
    std::vector<Candidate> heap;
    std::unordered_map<std::uint64_t, Hull> hulls; // true joint hulls computed so far, by pair
    bool siblingsOnly = true;
    auto consider = [&](std::size_t i, std::size_t j) {
        if (siblingsOnly && origin[i] != origin[j])
            return;
        const double tol = 1e-9 * (bounds[i].diagonal() + bounds[j].diagonal());
        if (!bounds[i].overlaps(bounds[j], tol))
            return;
        Aabb joint = bounds[i], common;
        joint.extend(bounds[j]);
        common.lo = max(bounds[i].lo, bounds[j].lo);
        common.hi = min(bounds[i].hi, bounds[j].hi);
        const double added =
            boxVolume(joint) - boxVolume(bounds[i]) - boxVolume(bounds[j]) + boxVolume(common);
        // A pair that covered a crater still does once either part has grown (hulls only grow).
        const bool covers = guard && std::find(blocked[i].begin(), blocked[i].end(), j) != blocked[i].end();
        heap.push_back({added, i, j, version[i], version[j], covers});
        std::push_heap(heap.begin(), heap.end(), std::greater<>());
    };
    auto jointHull = [&](const Candidate& c) -> Hull* {
        const std::uint64_t key = static_cast<std::uint64_t>(c.i) * n + c.j;
        auto it = hulls.find(key);
        if (it != hulls.end() && it->second.vi == c.vi && it->second.vj == c.vj)
            return &it->second;
        for (std::size_t k : {c.i, c.j})
            if (corners[k].empty())
                corners[k] = parts[k].vertices();
        std::vector<Vec3> pts = corners[c.i];
        pts.insert(pts.end(), corners[c.j].begin(), corners[c.j].end());
        auto h = detail::hullOfFew(pts);
        if (!h)
            return nullptr;
        const double cost = h->volume() - volumes[c.i] - volumes[c.j];
        Overlaps overlaps = guard ? guard->overlaps(*h) : Overlaps{};
        Overlaps added = CellGuard::added(overlaps, owned[c.i], owned[c.j]);
        Hull& slot = hulls[key];
        slot = {c.vi, c.vj, cost, std::move(h.value()), std::move(overlaps), std::move(added)};
        return &slot;
    };
    // Pairs whose boxes can touch, by a sweep along x over the current boxes (consider checks the exact
    // tolerance).
    auto forEachNearPair = [&](auto&& fn) {
        double reach = 0;
        std::vector<std::size_t> byX;
        for (std::size_t i = 0; i < n; ++i)
            if (alive[i]) {
                byX.push_back(i);
                reach = std::max(reach, 2e-9 * bounds[i].diagonal());
            }
        std::sort(byX.begin(), byX.end(), [&](std::size_t a, std::size_t b) {
            return bounds[a].lo.x < bounds[b].lo.x || (bounds[a].lo.x == bounds[b].lo.x && a < b);
        });
        for (std::size_t a = 0; a < byX.size(); ++a)
            for (std::size_t b = a + 1; b < byX.size() && bounds[byX[b]].lo.x <= bounds[byX[a]].hi.x + reach;
                 ++b)
                fn(std::min(byX[a], byX[b]), std::max(byX[a], byX[b]));
    };
    forEachNearPair(consider);
    // Pairs refused by a lower bound get their true hull and excess once a covering pair is to be taken.
    std::size_t estimated = 0;
    auto settleEstimates = [&] {
        std::vector<Candidate> settled;
        for (Candidate& c : heap) {
            if (c.estimated && alive[c.i] && alive[c.j] && version[c.i] == c.vi && version[c.j] == c.vj) {
                const Hull* h = jointHull(c);
                if (!h)
                    continue;
                c.cost = guard->excessAt(h->added, c.epoch);
                c.estimated = false;
            }
            settled.push_back(c);
        }
        heap = std::move(settled);
        std::make_heap(heap.begin(), heap.end(), std::greater<>());
        estimated = 0;
    };
    std::size_t count = n, limit = budget;
    std::vector<Candidate> picked;
    while (count > limit) {
        picked.clear();
        while (picked.size() < verified && !heap.empty()) {
            if (heap.front().covers && (siblingsOnly || !picked.empty()))
                break; // pairs that cover a crater wait for every other pair
            if (heap.front().covers && count <= stretch) {
                limit = count; // a crater kept open is worth a few more parts
                break;
            }
            if (heap.front().covers && estimated > 0) {
                settleEstimates();
                continue;
            }
            std::pop_heap(heap.begin(), heap.end(), std::greater<>());
            const Candidate c = heap.back();
            heap.pop_back();
            if (alive[c.i] && alive[c.j] && version[c.i] == c.vi && version[c.j] == c.vj)
                picked.push_back(c);
        }
        if (picked.empty()) {
            if (!siblingsOnly)
                break;
            siblingsOnly = false; // siblings were not enough: every touching pair
            forEachNearPair([&](std::size_t i, std::size_t j) {
                if (alive[i] && alive[j] && origin[i] != origin[j])
                    consider(i, j);
            });
            continue;
        }
        std::size_t best = picked.size();
        Hull* bestHull = nullptr;
        std::vector<bool> failed(picked.size(), false);
        auto refuse = [&](Candidate& c, double e) { // ranked again behind the others
            c.covers = true;
            c.cost = e;
            blocked[c.i].push_back(c.j);
            blocked[c.j].push_back(c.i);
            heap.push_back(c);
            std::push_heap(heap.begin(), heap.end(), std::greater<>());
        };
        for (std::size_t k = 0; k < picked.size(); ++k) {
            Candidate& c = picked[k];
            if (guard && !c.covers)
                if (const double e = guard->excessAtLeast(parts[c.i], owned[c.i], parts[c.j], owned[c.j]);
                    e > 0) {
                    c.estimated = true;
                    c.epoch = guard->epoch();
                    ++estimated;
                    refuse(c, e);
                    failed[k] = true;
                    continue;
                }
            Hull* h = jointHull(c);
            failed[k] = h == nullptr;
            if (h && guard && !c.covers) {
                if (const double e = guard->excess(h->added); e > 0) {
                    refuse(c, e);
                    failed[k] = true;
                    continue;
                }
            }
            if (h && (!bestHull || h->cost < bestHull->cost)) {
                best = k;
                bestHull = h;
            }
        }
        for (std::size_t k = 0; k < picked.size(); ++k)
            if (k != best && !failed[k]) { // ranked again next round; a pair whose hull failed is dropped
                heap.push_back(picked[k]);
                std::push_heap(heap.begin(), heap.end(), std::greater<>());
            }
        if (!bestHull)
            continue;
        const Candidate c = picked[best];
        if (guard)
            guard->take(bestHull->added);
        if (c.covers) // the craters cannot all stay open: the rest merges as without a guard
            guard = nullptr;
        owned[c.i] = std::move(bestHull->overlaps);
        const std::vector<std::size_t> partners = blocked[c.j]; // a copy: the loop grows these lists
        for (std::size_t k : partners) {
            if (k == c.i || k == c.j)
                continue;
            blocked[c.i].push_back(k);
            blocked[k].push_back(c.i);
        }
        parts[c.i] = std::move(bestHull->shape);
        bounds[c.i] = parts[c.i].bounds();
        volumes[c.i] = parts[c.i].volume();
        corners[c.i].clear();
        ++version[c.i];
        alive[c.j] = false;
        --count;
        for (std::size_t k = 0; k < n; ++k)
            if (k != c.i && alive[k])
                consider(std::min(k, c.i), std::max(k, c.i));
    }
    std::vector<ConvexPolytope> kept;
    for (std::size_t i = 0; i < n; ++i)
        if (alive[i])
            kept.push_back(std::move(parts[i]));
    // Parts that touch nothing are kept whole; if still over budget, the smallest go.
    if (kept.size() > limit) {
        std::sort(kept.begin(), kept.end(),
                  [](const ConvexPolytope& a, const ConvexPolytope& b) { return a.volume() > b.volume(); });
        kept.resize(limit);
    }
    parts = std::move(kept);
}

/// The pieces of a fracture, each with its class: its cell, or −1 for a remainder island.
struct PieceSet {
    const std::vector<const Mesh*>& meshes;
    const std::vector<std::int32_t>& cells;
    std::size_t size() const { return meshes.size(); }
    std::int32_t cellOf(std::size_t i) const { return i < cells.size() ? cells[i] : -1; }
};

/// Stage 1, fragments: every parent part cut into part ∩ cell_c and what is left outside every cell; adds the
/// parts' volume to parentVolume.
std::vector<Fragment> cutFragments(const std::vector<ConvexPolytope>& parentParts,
                                   const std::vector<ConvexPolytope>& cells,
                                   const std::vector<Aabb>& cellBounds, double& parentVolume) {
    std::vector<Fragment> fragments;
    const std::vector<OuterFace> outer = outerFaces(cells, cellBounds);
    for (std::uint32_t partIndex = 0; partIndex < parentParts.size(); ++partIndex) {
        const ConvexPolytope& part = parentParts[partIndex];
        parentVolume += part.volume();
        const Aabb pb = part.bounds();
        for (std::size_t c = 0; c < cells.size(); ++c) {
            if (!pb.overlaps(cellBounds[c]))
                continue;
            ConvexPolytope inside = intersectCell(part, cells[c]);
            if (!inside.empty())
                fragments.push_back({std::move(inside), static_cast<std::int32_t>(c), partIndex});
        }
        // part − every cell.
        std::vector<ConvexPolytope> rest;
        subtractUnion(part, cells, cellBounds, outer, 0, rest);
        for (ConvexPolytope& r : rest)
            fragments.push_back({std::move(r), -1, partIndex});
    }
    return fragments;
}

/// Stage 2, slivers: numerical leftovers (volume up to `sliver`) always; fragments up to `small` only when
/// flat (a small but chunky fragment may hold a piece's corner and is merged into a neighbour instead).
bool isSliver(const ConvexPolytope& shape, double volume, double sliver, double small) {
    if (volume <= sliver)
        return true;
    if (volume <= small) {
        const double d = shape.bounds().diagonal();
        if (volume < 1e-7 * d * d * d)
            return true; // flat: thinner than about 1e-7 of its size
    }
    return false;
}

/// The fragments each piece received.
struct Assignment {
    std::vector<std::vector<ConvexPolytope>> parts;  ///< per piece
    std::vector<std::vector<std::uint32_t>> origins; ///< parent part of each part
    std::vector<bool> trim;                          ///< fragments are clipped to the piece's bounds
    std::vector<Aabb> bounds;                        ///< per piece
};

/// Stage 3, assignment: every fragment that is no sliver goes to the piece of its class containing it.
Assignment assignFragments(std::vector<Fragment>& fragments, const std::vector<ConvexPolytope>& parentParts,
                           const PieceSet& pieces, double parentVolume, const DecompositionParams& params) {
    std::size_t totalTriangles = 0;
    for (const Mesh* piece : pieces.meshes)
        totalTriangles += piece->triangles.size();
    const bool highPolyParent = totalTriangles > params.proxyAboveTriangles;
    const double sliver = 1e-12 * parentVolume;
    const double small = params.minPartVolumeFraction * parentVolume;
    Assignment a;
    a.parts.resize(pieces.size());
    a.origins.resize(pieces.size());
    auto give = [&](std::size_t piece, ConvexPolytope part, std::uint32_t origin) {
        a.parts[piece].push_back(std::move(part));
        a.origins[piece].push_back(origin);
    };
    // A high-poly remainder island alone in its class takes every remainder fragment as it is: its bounds
    // (a pass over its vertices) are replaced by the parent parts' (which cover it), and nothing is trimmed.
    std::size_t remainders = 0;
    for (std::size_t i = 0; i < pieces.size(); ++i)
        remainders += pieces.cellOf(i) < 0 ? 1 : 0;
    a.trim.assign(pieces.size(), true);
    a.bounds.resize(pieces.size());
    for (std::size_t i = 0; i < pieces.size(); ++i) {
        if (pieces.cellOf(i) < 0 && remainders == 1 &&
            pieces.meshes[i]->triangles.size() > params.proxyAboveTriangles) {
            a.trim[i] = false;
            for (const ConvexPolytope& part : parentParts)
                a.bounds[i].extend(part.bounds());
        } else {
            a.bounds[i] = pieces.meshes[i]->bounds();
        }
    }
    for (Fragment& frag : fragments) {
        if (isSliver(frag.shape, frag.shape.volume(), sliver, small))
            continue;
        const Aabb fb = frag.shape.bounds();
        const double tol = 1e-9 * (fb.diagonal() + 1);
        std::vector<std::size_t> candidates;
        for (std::size_t i = 0; i < pieces.size(); ++i)
            if (pieces.cellOf(i) == frag.cell && a.bounds[i].overlaps(fb, tol))
                candidates.push_back(i);
        if (candidates.size() == 1) {
            if (!a.trim[candidates[0]]) {
                give(candidates[0], std::move(frag.shape), frag.part);
                continue;
            }
            // Parent parts may reach into empty space: keep the fragment inside the piece's bounds.
            ConvexPolytope clipped = clippedToBox(std::move(frag.shape), a.bounds[candidates[0]]);
            if (!clipped.empty())
                give(candidates[0], std::move(clipped), frag.part);
            continue;
        }
        if (candidates.size() > 1) {
            // Several islands may share this fragment: give each the hull of its own part inside it (when the
            // island or the parent is high-poly, whose inside test costs a pass over the island per corner of
            // a bounded part, the fragment clipped to the island's bounds, which also holds that part).
            for (std::size_t i : candidates) {
                if (highPolyParent || pieces.meshes[i]->triangles.size() > params.proxyAboveTriangles) {
                    ConvexPolytope clipped = clippedToBox(frag.shape, a.bounds[i]);
                    if (!clipped.empty() && clipped.volume() > sliver)
                        give(i, std::move(clipped), frag.part);
                    continue;
                }
                auto h = detail::hullOfMeshInRegion(*pieces.meshes[i], frag.shape);
                if (h && h->volume() > sliver)
                    give(i, std::move(h.value()), frag.part);
            }
            continue;
        }
        // No piece of the matching class overlaps: nearest piece by bounds.
        const Vec3 c = frag.shape.centroid();
        std::size_t best = 0;
        double bestDist = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < pieces.size(); ++i) {
            const double d = distanceToBox(a.bounds[i], c);
            if (d < bestDist) {
                bestDist = d;
                best = i;
            }
        }
        // A fragment lying in empty space away from every piece is dropped.
        if (bestDist <= 1e-6 * (a.bounds[best].diagonal() + fb.diagonal())) {
            ConvexPolytope clipped = clippedToBox(std::move(frag.shape), a.bounds[best]);
            if (!clipped.empty())
                give(best, std::move(clipped), frag.part);
        }
    }
    return a;
}

/// Stage 4, fitting, for piece i: one hull when its fragments fill it, else merged to the budget (a
/// remainder's parts kept out of the cells' debris); a fresh decomposition when nothing arrived.
void fitPiece(std::size_t i, Assignment& a, const PieceSet& pieces,
              const std::vector<ConvexPolytope>& parentParts, const std::vector<ConvexPolytope>& cells,
              const std::vector<Aabb>& cellBounds, const std::vector<double>& debrisVolume,
              const DecompositionParams& params) {
    std::vector<ConvexPolytope>& parts = a.parts[i];
    // A remainder's parts stay out of the cells (a debris piece's stay in its own cell by construction).
    std::optional<CellGuard> guard;
    if (pieces.cellOf(i) < 0 && !parts.empty()) {
        double own = 0;
        for (const ConvexPolytope& p : parts)
            own += p.volume();
        std::vector<double> allowance(cells.size(), std::numeric_limits<double>::infinity());
        for (std::size_t c = 0; c < cells.size(); ++c)
            if (debrisVolume[c] > 0)
                allowance[c] = kOverlapShare * kPartOverlapTolerance * std::min(own, debrisVolume[c]);
        guard.emplace(cells, cellBounds, std::move(allowance));
    }
    CellGuard* g = guard ? &*guard : nullptr;
    if (parts.empty()) {
        auto d = decompose(*pieces.meshes[i], params);
        if (d)
            parts = std::move(d->parts);
        return;
    }
    // A high-poly remainder island is its parent's parts (which did not fill their hull, or they would be
    // one) and their fragments, dented by the cells: the test for whether they fill their hull (a hull of
    // every corner) is skipped. Over the budget, its least dented parts are made whole again.
    const bool highPoly = pieces.meshes[i]->triangles.size() > params.proxyAboveTriangles;
    const bool dented = i < pieces.cells.size() && pieces.cells[i] < 0 && highPoly;
    if (dented && parts.size() > static_cast<std::size_t>(params.maxParts))
        revertToParents(parts, a.origins[i], parentParts, static_cast<std::size_t>(params.maxParts),
                        kHighPolyFillTolerance, a.trim[i] ? &a.bounds[i] : nullptr, g);
    // A high-poly piece's parts that nearly fill their hull become that hull (kHighPolyFillTolerance).
    if (parts.size() > 1 && !dented) {
        double sum = 0;
        std::vector<Vec3> pts;
        for (const ConvexPolytope& p : parts) {
            sum += p.volume();
            if (highPoly) { // corners as they are (repeats do not change a hull; welding is a sort)
                for (const PolytopeFaceView& f : p.faces())
                    pts.insert(pts.end(), f.corners.begin(), f.corners.end());
                continue;
            }
            const auto v = p.vertices();
            pts.insert(pts.end(), v.begin(), v.end());
        }
        // The hull of the extremes in 26 directions lies inside the full hull: when it is already larger
        // than the parts together, they do not fill their hull (and the full hull is not computed).
        const double fillTol = highPoly ? kHighPolyFillTolerance : 1e-6;
        if (auto quick = detail::hullOfFew(extremePoints(pts));
            quick && quick->volume() > sum * (1 + fillTol)) {
            mergeToBudget(parts, a.origins[i], params.maxParts, g);
            return;
        }
        auto h = detail::hullOfFew(pts);
        if (h && h->volume() <= sum * (1 + fillTol) && (!g || g->excess(g->overlaps(*h)) <= 0)) {
            parts.clear();
            parts.push_back(std::move(h.value()));
            return;
        }
    }
    mergeToBudget(parts, a.origins[i], params.maxParts, g);
}

/// Stage 5, bounds: parts kept to a bounded size, so that the next hit clips the same few faces, and inside
/// their piece's convex hull (kPartHullTolerance): clipped by its exact hull up to proxyAboveTriangles, and
/// above, every part with a corner not proven near the hull (detail::HullWitness) replaced by the hull of the
/// piece's points it holds (docs/collision.md).
void boundToHull(std::vector<ConvexPolytope>& parts, const Mesh& piece, const DecompositionParams& params) {
    if (parts.empty())
        return;
    const double reach = detail::kHullReachShare * partHullTolerance(piece.bounds().diagonal());
    const bool highPoly = piece.triangles.size() > params.proxyAboveTriangles;
    std::optional<ConvexPolytope> hull;
    if (!highPoly)
        if (auto h = convexHull(piece.positions))
            hull = std::move(h.value());
    if (hull)
        detail::keepInsideHull(parts, *hull, 1e-9 * piece.bounds().diagonal());
    bool bounded = false;
    for (ConvexPolytope& p : parts)
        if (p.faces().size() > params.maxPartFaces)
            if (auto b = boundedHull(p.vertices(), params.maxPartFaces)) {
                p = std::move(b.value());
                bounded = true;
            }
    if (highPoly || (hull && bounded))
        detail::keepNearHull(parts, piece, reach, params.maxPartFaces, hull ? &*hull : nullptr);
}

/// updateDecomposition on pieces held elsewhere (no copies): the five stages.
std::vector<std::vector<ConvexPolytope>> updateParts(const std::vector<ConvexPolytope>& parentParts,
                                                     const std::vector<ConvexPolytope>& cells,
                                                     const std::vector<const Mesh*>& meshes,
                                                     const std::vector<std::int32_t>& pieceCells,
                                                     const DecompositionParams& params) {
    if (meshes.empty())
        return {};
    const PieceSet pieces{meshes, pieceCells};
    std::vector<Aabb> cellBounds;
    cellBounds.reserve(cells.size());
    for (const ConvexPolytope& cell : cells)
        cellBounds.push_back(cell.bounds());
    double parentVolume = 0;
    std::vector<Fragment> fragments = cutFragments(parentParts, cells, cellBounds, parentVolume);
    Assignment assigned = assignFragments(fragments, parentParts, pieces, parentVolume, params);
    // Volume of the debris of each cell: what a remainder's parts must not cover (kPartOverlapTolerance).
    std::vector<double> debrisVolume(cells.size(), 0);
    for (std::size_t i = 0; i < pieces.size(); ++i)
        if (const std::int32_t cell = pieces.cellOf(i);
            cell >= 0 && static_cast<std::size_t>(cell) < cells.size())
            debrisVolume[static_cast<std::size_t>(cell)] += std::abs(signedVolume(*meshes[i]));
    for (std::size_t i = 0; i < pieces.size(); ++i)
        fitPiece(i, assigned, pieces, parentParts, cells, cellBounds, debrisVolume, params);
    for (std::size_t i = 0; i < pieces.size(); ++i)
        boundToHull(assigned.parts[i], *meshes[i], params);
    return std::move(assigned.parts);
}

} // namespace

std::vector<std::vector<ConvexPolytope>> updateDecomposition(const std::vector<ConvexPolytope>& parentParts,
                                                             const std::vector<ConvexPolytope>& cells,
                                                             const std::vector<Mesh>& pieces,
                                                             const std::vector<std::int32_t>& pieceCells,
                                                             const DecompositionParams& params) {
    std::vector<const Mesh*> held;
    held.reserve(pieces.size());
    for (const Mesh& m : pieces)
        held.push_back(&m);
    return updateParts(parentParts, cells, held, pieceCells, params);
}

std::vector<std::vector<ConvexPolytope>> updateDecomposition(const std::vector<ConvexPolytope>& parentParts,
                                                             const FractureResult& result,
                                                             const DecompositionParams& params) {
    std::vector<const Mesh*> meshes;
    std::vector<std::int32_t> pieceCells;
    for (const Piece& piece : result.pieces) {
        meshes.push_back(&piece.mesh);
        pieceCells.push_back(piece.cell);
    }
    return updateParts(parentParts, result.cells, meshes, pieceCells, params);
}

} // namespace rubble
