#include "rubble/structure/BondGraph.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rubble {

namespace {

struct Patch {
    std::vector<Vec3> corners; // on the first solid's face plane
    Vec3 normal;
};

double cross2(const Vec2& a, const Vec2& b) {
    return a.x * b.y - a.y * b.x;
}

// Clips convex polygon `poly` (counter-clockwise) by convex polygon `clip` (counter-clockwise).
std::vector<Vec2> clipConvex(std::vector<Vec2> poly, const std::vector<Vec2>& clip) {
    for (std::size_t i = 0; i < clip.size() && !poly.empty(); ++i) {
        const Vec2 p = clip[i], q = clip[(i + 1) % clip.size()];
        const Vec2 e{q.x - p.x, q.y - p.y};
        auto side = [&](const Vec2& x) { return cross2(e, Vec2{x.x - p.x, x.y - p.y}); };
        std::vector<Vec2> out;
        for (std::size_t j = 0; j < poly.size(); ++j) {
            const Vec2 c = poly[j], n = poly[(j + 1) % poly.size()];
            const double sc = side(c), sn = side(n);
            if (sc >= 0)
                out.push_back(c);
            if ((sc >= 0) != (sn >= 0)) {
                const double t = sc / (sc - sn);
                out.push_back({c.x + t * (n.x - c.x), c.y + t * (n.y - c.y)});
            }
        }
        poly = std::move(out);
    }
    return poly;
}

void basisOf(const Vec3& n, Vec3& u, Vec3& v) {
    const Vec3 helper =
        std::abs(n.x) < 0.6 ? Vec3{1, 0, 0} : (std::abs(n.y) < 0.6 ? Vec3{0, 1, 0} : Vec3{0, 0, 1});
    u = normalized(cross(helper, n));
    v = cross(n, u);
}

// The overlap of face fa (of the first solid) and fb (of the second), or nothing.
void facePatch(const PolytopeFaceView& fa, const PolytopeFaceView& fb, const BondSettings& s,
               std::vector<Patch>& out) {
    const double cosTol = std::cos(s.angleTolerance * std::numbers::pi / 180);
    if (dot(fa.plane.normal, fb.plane.normal) > -cosTol)
        return;
    for (const Vec3& c : fb.corners)
        if (std::abs(fa.plane.signedDistance(c)) > s.gap)
            return;
    Vec3 u, v;
    basisOf(fa.plane.normal, u, v);
    const Vec3 o = fa.corners.front();
    std::vector<Vec2> pa, pb;
    for (const Vec3& c : fa.corners)
        pa.push_back({dot(c - o, u), dot(c - o, v)});
    // fb is counter-clockwise about its own normal (opposite), so clockwise here: reverse it.
    for (std::size_t i = fb.corners.size(); i-- > 0;)
        pb.push_back({dot(fb.corners[i] - o, u), dot(fb.corners[i] - o, v)});
    const std::vector<Vec2> ov = clipConvex(pb, pa);
    if (ov.size() < 3)
        return;
    Patch p;
    p.normal = fa.plane.normal;
    for (const Vec2& q : ov)
        p.corners.push_back(o + u * q.x + v * q.y);
    out.push_back(std::move(p));
}

// Area, first and second moments of a polygon in (s, t) about the origin.
struct Moments {
    double area = 0, s = 0, t = 0, ss = 0, tt = 0, st = 0;
};

Moments polygonMoments(const std::vector<Vec2>& p) {
    Moments m;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec2 a = p[i], b = p[(i + 1) % p.size()];
        const double w = a.x * b.y - b.x * a.y;
        m.area += w / 2;
        m.s += (a.x + b.x) * w / 6;
        m.t += (a.y + b.y) * w / 6;
        m.ss += (a.x * a.x + a.x * b.x + b.x * b.x) * w / 12;
        m.tt += (a.y * a.y + a.y * b.y + b.y * b.y) * w / 12;
        m.st += (a.x * b.y + 2 * a.x * a.y + 2 * b.x * b.y + b.x * a.y) * w / 24;
    }
    return m;
}

bool apart(const Aabb& p, const Aabb& q, double gap) {
    return p.hi.x + gap < q.lo.x || q.hi.x + gap < p.lo.x || p.hi.y + gap < q.lo.y || q.hi.y + gap < p.lo.y ||
           p.hi.z + gap < q.lo.z || q.hi.z + gap < p.lo.z;
}

// Bonds in (a, b) order.
bool byNodes(const Bond& x, const Bond& y) {
    return x.a < y.a || (x.a == y.a && x.b < y.b);
}

} // namespace

BondInterface bondInterface(const std::vector<ConvexPolytope>& a, const std::vector<ConvexPolytope>& b,
                            const BondSettings& settings) {
    std::vector<Patch> patches;
    for (const ConvexPolytope& pa : a)
        for (const ConvexPolytope& pb : b) {
            if (apart(pa.bounds(), pb.bounds(), settings.gap))
                continue;
            for (const PolytopeFaceView& fa : pa.faces())
                for (const PolytopeFaceView& fb : pb.faces())
                    facePatch(fa, fb, settings, patches);
        }
    BondInterface out;
    // Area-weighted normal and a common basis; then every patch's moments about the common centroid.
    Vec3 n, largest;
    double area = 0, largestArea = 0;
    for (const Patch& p : patches) {
        Vec3 twice;
        for (std::size_t i = 1; i + 1 < p.corners.size(); ++i)
            twice += cross(p.corners[i] - p.corners[0], p.corners[i + 1] - p.corners[0]);
        n += twice;
        area += length(twice) / 2;
        if (length(twice) / 2 > largestArea) {
            largestArea = length(twice) / 2;
            largest = p.normal;
        }
    }
    if (area < settings.minArea)
        return out;
    // Patches around a corner may nearly cancel: then the largest patch's normal.
    out.normal = length(n) / 2 > 0.1 * area ? normalized(n) : largest;
    basisOf(out.normal, out.u, out.v);
    Moments total;
    std::vector<std::vector<Vec2>> flat;
    for (const Patch& p : patches) {
        std::vector<Vec2> q;
        for (const Vec3& c : p.corners)
            q.push_back({dot(c, out.u), dot(c, out.v)});
        Moments m = polygonMoments(q);
        if (m.area < 0) { // a patch facing away from the mean normal
            std::reverse(q.begin(), q.end());
            m = polygonMoments(q);
        }
        total.area += m.area;
        total.s += m.s;
        total.t += m.t;
        total.ss += m.ss;
        total.tt += m.tt;
        total.st += m.st;
        flat.push_back(std::move(q));
    }
    if (total.area <= 0)
        return out;
    const double cs = total.s / total.area, ct = total.t / total.area;
    double depth = 0, weight = 0;
    for (const Patch& p : patches)
        for (const Vec3& c : p.corners) {
            depth += dot(c, out.normal);
            weight += 1;
        }
    out.area = area;
    out.sectionArea = total.area;
    out.centroid = out.u * cs + out.v * ct + out.normal * (depth / weight);
    out.ivv = total.ss - total.area * cs * cs;
    out.iuu = total.tt - total.area * ct * ct;
    out.iuv = total.st - total.area * cs * ct;
    for (const auto& q : flat)
        for (const Vec2& c : q)
            out.corners.push_back({c.x - cs, c.y - ct});
    return out;
}

std::vector<Bond> buildBonds(const std::vector<std::vector<ConvexPolytope>>& solids,
                             const BondSettings& settings) {
    struct Entry {
        Aabb box;
        std::uint32_t id;
    };
    std::vector<Entry> entries;
    for (std::uint32_t i = 0; i < solids.size(); ++i) {
        Aabb box;
        for (const ConvexPolytope& p : solids[i])
            box.extend(p.bounds());
        if (!solids[i].empty())
            entries.push_back({box, i});
    }
    std::sort(entries.begin(), entries.end(), [](const Entry& x, const Entry& y) {
        return x.box.lo.x < y.box.lo.x || (x.box.lo.x == y.box.lo.x && x.id < y.id);
    });
    std::vector<Bond> bonds;
    for (std::size_t i = 0; i < entries.size(); ++i)
        for (std::size_t j = i + 1;
             j < entries.size() && entries[j].box.lo.x <= entries[i].box.hi.x + settings.gap; ++j) {
            if (apart(entries[i].box, entries[j].box, settings.gap))
                continue;
            const std::uint32_t a = std::min(entries[i].id, entries[j].id),
                                b = std::max(entries[i].id, entries[j].id);
            BondInterface s = bondInterface(solids[a], solids[b], settings);
            if (s.area > 0)
                bonds.push_back({a, b, std::move(s)});
        }
    std::sort(bonds.begin(), bonds.end(), byNodes);
    return bonds;
}

namespace {

constexpr std::int64_t kMaxCells = 512; // a solid spanning more grid cells is checked against every add

Aabb boundsOf(const std::vector<ConvexPolytope>& parts) {
    Aabb box;
    for (const ConvexPolytope& p : parts)
        box.extend(p.bounds());
    return box;
}

} // namespace

BondGraph::BondGraph(BondSettings settings, double cellSize) : settings_(settings), cellSize_(cellSize) {}

std::uint64_t BondGraph::cellKey(std::int64_t x, std::int64_t y, std::int64_t z) const {
    // 21 bits per axis (wrapping): distinct cells may share a key, which only adds candidates
    const auto bits = [](std::int64_t v) { return static_cast<std::uint64_t>(v) & 0x1fffff; };
    return bits(x) | (bits(y) << 21) | (bits(z) << 42);
}

std::vector<Bond> BondGraph::add(std::uint32_t id, std::vector<ConvexPolytope> parts) {
    Solid s;
    s.parts = std::move(parts);
    s.box = boundsOf(s.parts);
    std::vector<std::uint32_t> candidates;
    if (!s.parts.empty()) {
        std::int64_t cells = 1;
        for (int k = 0; k < 3; ++k) {
            s.lo[k] = static_cast<std::int64_t>(std::floor((s.box.lo[k] - settings_.gap) / cellSize_));
            s.hi[k] = static_cast<std::int64_t>(std::floor((s.box.hi[k] + settings_.gap) / cellSize_));
            cells *= std::min<std::int64_t>(s.hi[k] - s.lo[k] + 1, kMaxCells + 1);
        }
        s.large = cells > kMaxCells;
        if (s.large) {
            for (const auto& [other, o] : solids_)
                candidates.push_back(other);
        } else {
            for (std::int64_t x = s.lo[0]; x <= s.hi[0]; ++x)
                for (std::int64_t y = s.lo[1]; y <= s.hi[1]; ++y)
                    for (std::int64_t z = s.lo[2]; z <= s.hi[2]; ++z) {
                        std::vector<std::uint32_t>& cell = cells_[cellKey(x, y, z)];
                        candidates.insert(candidates.end(), cell.begin(), cell.end());
                        cell.push_back(id);
                    }
            candidates.insert(candidates.end(), large_.begin(), large_.end());
        }
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    lastCandidates_ = candidates.size();
    std::vector<Bond> out;
    for (std::uint32_t other : candidates) {
        Solid& o = solids_.at(other);
        if (o.parts.empty() || apart(s.box, o.box, settings_.gap))
            continue;
        const std::uint32_t a = std::min(id, other), b = std::max(id, other);
        BondInterface x = bondInterface(a == id ? s.parts : o.parts, a == id ? o.parts : s.parts, settings_);
        if (x.area <= 0)
            continue;
        s.adjacent.push_back(other);
        o.adjacent.push_back(id);
        bonds_.emplace(key(a, b), x);
        out.push_back({a, b, std::move(x)});
    }
    if (s.large)
        large_.push_back(id);
    solids_.emplace(id, std::move(s));
    return out;
}

std::vector<std::uint32_t> BondGraph::remove(std::uint32_t id) {
    const auto it = solids_.find(id);
    if (it == solids_.end())
        return {};
    Solid& s = it->second;
    if (s.large)
        std::erase(large_, id);
    else if (!s.parts.empty())
        for (std::int64_t x = s.lo[0]; x <= s.hi[0]; ++x)
            for (std::int64_t y = s.lo[1]; y <= s.hi[1]; ++y)
                for (std::int64_t z = s.lo[2]; z <= s.hi[2]; ++z) {
                    const auto cell = cells_.find(cellKey(x, y, z));
                    std::erase(cell->second, id);
                    if (cell->second.empty())
                        cells_.erase(cell);
                }
    std::vector<std::uint32_t> out = std::move(s.adjacent);
    for (std::uint32_t other : out) {
        std::erase(solids_.at(other).adjacent, id);
        bonds_.erase(key(std::min(id, other), std::max(id, other)));
    }
    solids_.erase(it);
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<Bond> BondGraph::bonds() const {
    std::vector<Bond> out;
    for (const auto& [k, x] : bonds_)
        out.push_back({static_cast<std::uint32_t>(k >> 32), static_cast<std::uint32_t>(k), x});
    std::sort(out.begin(), out.end(), byNodes);
    return out;
}

} // namespace rubble
