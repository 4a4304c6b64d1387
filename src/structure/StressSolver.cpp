#include "rubble/StressSolver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "rubble/MassProperties.hpp"

namespace rubble {

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;

Eigen::Matrix3d toEigen(const Mat3& m) {
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            r(i, j) = m.m[i][j];
    return r;
}

Eigen::Matrix3d skew(const Vec3& r) {
    Eigen::Matrix3d s;
    s << 0, -r.z, r.y, r.z, 0, -r.x, -r.y, r.x, 0;
    return s;
}

Mat3 inverse(const Mat3& m) {
    const Eigen::Matrix3d e = toEigen(m);
    Mat3 r;
    if (std::abs(e.determinant()) <= 0)
        return r;
    const Eigen::Matrix3d inv = e.inverse();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            r.m[i][j] = inv(i, j);
    return r;
}

// Counter-clockwise convex hull (Andrew's monotone chain).
std::vector<Vec2> convexHull(std::vector<Vec2> pts) {
    std::sort(pts.begin(), pts.end(),
              [](const Vec2& a, const Vec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    if (pts.size() < 3)
        return pts;
    auto turn = [](const Vec2& o, const Vec2& a, const Vec2& b) {
        return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
    };
    std::vector<Vec2> h(2 * pts.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
        while (k >= 2 && turn(h[k - 2], h[k - 1], pts[i]) <= 0)
            --k;
        h[k++] = pts[i];
    }
    for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
        while (k >= t && turn(h[k - 2], h[k - 1], pts[i - 1]) <= 0)
            --k;
        h[k++] = pts[i - 1];
    }
    h.resize(k - 1);
    return h;
}

// At most 8 corners of the patch's hull (the extremes in 8 directions), counter-clockwise: a bearing's
// contact points. Exact for a rectangle; inside the hull otherwise, so tipping is judged conservatively.
std::vector<Vec2> bearingCorners(const std::vector<Vec2>& corners) {
    const std::vector<Vec2> hull = convexHull(corners);
    if (hull.size() <= 8)
        return hull;
    std::vector<std::size_t> picked;
    for (int k = 0; k < 8; ++k) {
        const double a = k * 3.14159265358979323846 / 4;
        const Vec2 d{std::cos(a), std::sin(a)};
        std::size_t best = 0;
        for (std::size_t i = 1; i < hull.size(); ++i)
            if (hull[i].x * d.x + hull[i].y * d.y > hull[best].x * d.x + hull[best].y * d.y)
                best = i;
        picked.push_back(best);
    }
    std::sort(picked.begin(), picked.end());
    picked.erase(std::unique(picked.begin(), picked.end()), picked.end());
    std::vector<Vec2> out;
    for (std::size_t i : picked)
        out.push_back(hull[i]);
    return out;
}

} // namespace

StructureNode structureNode(const std::vector<ConvexPolytope>& parts, double density, bool root) {
    StructureNode n;
    n.root = root;
    double volume = 0;
    Vec3 moment;
    std::vector<MassProperties> props;
    for (const ConvexPolytope& p : parts) {
        props.push_back(computeMassProperties(p.toMesh()));
        volume += props.back().volume;
        moment += props.back().centerOfMass * props.back().volume;
    }
    if (volume <= 0)
        return n;
    n.mass = volume * density;
    n.centroid = moment / volume;
    // Parallel-axis theorem: each part's inertia moved to the common centre of mass.
    for (const MassProperties& p : props) {
        const Vec3 d = p.centerOfMass - n.centroid;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                n.inertia.m[i][j] +=
                    density * (p.inertia.m[i][j] + p.volume * ((i == j ? dot(d, d) : 0.0) - d[i] * d[j]));
    }
    return n;
}

StrengthLimits bondLimits(const Material& a, const Material& b) {
    constexpr double mpa = 1e6;
    return {std::min(a.compressiveStrength, b.compressiveStrength) * mpa,
            std::min(a.tensileStrength, b.tensileStrength) * mpa,
            std::min(a.shearStrength, b.shearStrength) * mpa};
}

void StressSolver::reset(std::vector<StructureNode> nodes, std::vector<Bond> bonds,
                         std::vector<StrengthLimits> limits) {
    nodes_.clear();
    bonds_.clear();
    freeNodes_.clear();
    freeBonds_.clear();
    for (const StructureNode& n : nodes)
        (void)addNode(n);
    for (std::size_t i = 0; i < bonds.size(); ++i)
        (void)addBond(std::move(bonds[i]), i < limits.size() ? limits[i] : StrengthLimits{});
}

std::uint32_t StressSolver::addNode(const StructureNode& node) {
    NodeState s;
    s.node = node;
    if (!node.root && node.mass > 0) {
        s.invMass = 1 / node.mass;
        s.invInertia = inverse(node.inertia);
    }
    if (freeNodes_.empty()) {
        nodes_.push_back(std::move(s));
        return static_cast<std::uint32_t>(nodes_.size() - 1);
    }
    const std::uint32_t i = freeNodes_.back();
    freeNodes_.pop_back();
    nodes_[i] = std::move(s);
    return i;
}

void StressSolver::removeNode(std::uint32_t node) {
    NodeState& n = nodes_[node];
    if (n.removed)
        return;
    for (std::size_t b : std::vector<std::size_t>(n.bonds))
        removeBond(b);
    n = NodeState{};
    n.removed = n.detached = true;
    freeNodes_.insert(std::upper_bound(freeNodes_.begin(), freeNodes_.end(), node, std::greater<>()), node);
}

std::size_t StressSolver::addBond(Bond bond, StrengthLimits limits) {
    BondState s;
    s.bond = std::move(bond);
    s.limits = limits;
    prepare(s);
    std::size_t i = bonds_.size();
    if (freeBonds_.empty()) {
        bonds_.push_back(std::move(s));
    } else {
        i = freeBonds_.back();
        freeBonds_.pop_back();
        bonds_[i] = std::move(s);
    }
    for (std::uint32_t n : {bonds_[i].bond.a, bonds_[i].bond.b}) {
        std::vector<std::size_t>& list = nodes_[n].bonds;
        list.insert(std::upper_bound(list.begin(), list.end(), i), i);
        nodes_[n].bearings += limits.friction > 0;
    }
    return i;
}

void StressSolver::removeBond(std::size_t i) {
    BondState& b = bonds_[i];
    for (std::uint32_t n : {b.bond.a, b.bond.b}) {
        std::erase(nodes_[n].bonds, i);
        nodes_[n].bearings -= b.limits.friction > 0;
    }
    b = BondState{};
    b.removed = b.broken = true;
    freeBonds_.insert(std::upper_bound(freeBonds_.begin(), freeBonds_.end(), i, std::greater<>()), i);
}

void StressSolver::setRoot(std::uint32_t node, bool root) {
    NodeState& n = nodes_[node];
    n.node.root = root;
    n.invMass = 0;
    n.invInertia = Mat3{};
    if (!root && n.node.mass > 0) {
        n.invMass = 1 / n.node.mass;
        n.invInertia = inverse(n.node.inertia);
    }
    for (std::size_t i : n.bonds)
        prepare(bonds_[i]);
}

// The lever arms and the inverse effective masses of a bond (or of a bearing's corners).
void StressSolver::prepare(BondState& s) {
    const NodeState& a = nodes_[s.bond.a];
    const NodeState& b = nodes_[s.bond.b];
    s.ra = s.bond.section.centroid - a.node.centroid;
    s.rb = s.bond.section.centroid - b.node.centroid;
    s.solvable = false;
    if (s.limits.friction > 0) {
        const BondInterface& x = s.bond.section;
        auto inverseMass = [&](const Vec3& ra, const Vec3& rb, const Vec3& d) {
            const Vec3 ca = cross(ra, d), cb = cross(rb, d);
            return a.invMass + b.invMass + dot(ca, a.invInertia * ca) + dot(cb, b.invInertia * cb);
        };
        const std::vector<BearingCorner> old = std::move(s.corners);
        s.corners.clear();
        for (const Vec2& c : bearingCorners(x.corners)) {
            BearingCorner k;
            k.offset = x.u * c.x + x.v * c.y;
            k.ra = s.ra + k.offset;
            k.rb = s.rb + k.offset;
            k.kn = inverseMass(k.ra, k.rb, x.normal);
            k.ku = inverseMass(k.ra, k.rb, x.u);
            k.kv = inverseMass(k.ra, k.rb, x.v);
            const Vec3 dir[3] = {x.normal, x.u, x.v};
            for (int j = 0; j < 3; ++j) {
                k.ca[j] = cross(k.ra, dir[j]);
                k.cb[j] = cross(k.rb, dir[j]);
                k.ia[j] = a.invInertia * k.ca[j];
                k.ib[j] = b.invInertia * k.cb[j];
            }
            if (s.corners.size() < old.size()) { // keep the warm start
                k.press = old[s.corners.size()].press;
                k.gu = old[s.corners.size()].gu;
                k.gv = old[s.corners.size()].gv;
            }
            s.corners.push_back(k);
        }
        s.solvable = !s.corners.empty() && s.corners.front().kn > 0;
        return;
    }
    // Effective mass of the weld at the section centroid: impulse (P, L) on a, (-P, -L) on b.
    const Eigen::Matrix3d ia = toEigen(a.invInertia), ib = toEigen(b.invInertia);
    const Eigen::Matrix3d sa = skew(s.ra), sb = skew(s.rb);
    Mat6 k;
    k.topLeftCorner<3, 3>() =
        (a.invMass + b.invMass) * Eigen::Matrix3d::Identity() - sa * ia * sa - sb * ib * sb;
    k.topRightCorner<3, 3>() = -sa * ia - sb * ib;
    k.bottomLeftCorner<3, 3>() = ia * sa + ib * sb;
    k.bottomRightCorner<3, 3>() = ia + ib;
    const Eigen::FullPivLU<Mat6> lu(k);
    if (lu.isInvertible()) {
        const Mat6 inv = lu.inverse();
        for (int r = 0; r < 6; ++r)
            for (int c = 0; c < 6; ++c)
                s.kinv[r * 6 + c] = inv(r, c);
        s.solvable = true;
    }
}

void StressSolver::addLoad(std::uint32_t node, const Vec3& force, const Vec3& point) {
    NodeState& n = nodes_[node];
    n.force += force;
    n.torque += cross(point - n.node.centroid, force);
}

void StressSolver::apply(BondState& b, const Vec3& force, const Vec3& moment) {
    NodeState& na = nodes_[b.bond.a];
    NodeState& nb = nodes_[b.bond.b];
    na.v += force * na.invMass;
    na.w += na.invInertia * (cross(b.ra, force) + moment);
    nb.v -= force * nb.invMass;
    nb.w -= nb.invInertia * (cross(b.rb, force) + moment);
}

void StressSolver::solve() {
    // Unit time step: velocity changes are accelerations and accumulated impulses are forces.
    for (NodeState& n : nodes_) {
        if (n.invMass > 0 && !n.detached) {
            n.v = settings_.gravity + n.force * n.invMass;
            n.w = n.invInertia * n.torque;
        } else {
            n.v = n.w = Vec3{};
        }
        n.force = n.torque = Vec3{};
    }
    for (BondState& b : bonds_)
        if (!b.broken && b.solvable)
            apply(b, b.force, b.moment);
    // Sweeps stop early once every node a bond can still move is at rest within the tolerance.
    checked_.clear();
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
        if (nodes_[i].invMass > 0 && !nodes_[i].detached)
            for (std::size_t k : nodes_[i].bonds)
                if (!bonds_[k].broken && bonds_[k].solvable) {
                    checked_.push_back(i);
                    break;
                }
    const double tolerance2 = settings_.tolerance * settings_.tolerance;
    auto converged = [&] {
        if (settings_.tolerance <= 0)
            return false;
        for (std::uint32_t i : checked_)
            if (lengthSquared(nodes_[i].v) > tolerance2 || lengthSquared(nodes_[i].w) > tolerance2)
                return false;
        return true;
    };
    // A bond between two nodes at rest within a quarter of the tolerance would change by less: it is skipped
    // (within the whole tolerance, the nodes just below it would never be corrected, and the sweeps not end).
    const double quiet2 = tolerance2 / 16;
    auto resting = [&](const NodeState& n) {
        return settings_.tolerance > 0 && lengthSquared(n.v) <= quiet2 && lengthSquared(n.w) <= quiet2;
    };
    for (sweeps_ = 0; sweeps_ < settings_.iterations && !converged(); ++sweeps_)
        for (BondState& b : bonds_) {
            if (b.broken || !b.solvable || (resting(nodes_[b.bond.a]) && resting(nodes_[b.bond.b])))
                continue;
            if (!b.corners.empty()) {
                solveBearing(b);
                continue;
            }
            const NodeState& na = nodes_[b.bond.a];
            const NodeState& nb = nodes_[b.bond.b];
            const Vec3 lin = (na.v + cross(na.w, b.ra)) - (nb.v + cross(nb.w, b.rb));
            const Vec3 ang = na.w - nb.w;
            const double rel[6] = {lin.x, lin.y, lin.z, ang.x, ang.y, ang.z};
            double d[6];
            for (int r = 0; r < 6; ++r) {
                double sum = 0;
                for (int c = 0; c < 6; ++c)
                    sum += b.kinv[r * 6 + c] * rel[c];
                d[r] = -sum;
            }
            const Vec3 df{d[0], d[1], d[2]}, dm{d[3], d[4], d[5]};
            b.force += df;
            b.moment += dm;
            apply(b, df, dm);
        }
    for (BondState& b : bonds_)
        if (!b.broken && b.solvable && !b.corners.empty())
            gatherBearing(b);
    for (NodeState& n : nodes_) {
        const bool moving = length(n.v) > settings_.unbalanced || length(n.w) > settings_.unbalanced;
        n.unbalanced = n.bearings > 0 && n.invMass > 0 && !n.detached && moving ? n.unbalanced + 1 : 0;
    }
}

BondStress StressSolver::stress(std::size_t i) const {
    const BondState& b = bonds_[i];
    const BondInterface& s = b.bond.section;
    BondStress out;
    if (b.broken || s.sectionArea <= 0)
        return out;
    const double axial = dot(b.force, s.normal) / s.sectionArea; // > 0: b pulls a (tension)
    // Linear fibre stress sigma = alpha s + beta t whose moment about the centroid is the bond's couple.
    const double lu = dot(b.moment, s.u), lv = dot(b.moment, s.v);
    const double iss = s.ivv, itt = s.iuu, ist = s.iuv;
    const double det = ist * ist - itt * iss;
    double lo = axial, hi = axial, rmax = 0;
    if (std::abs(det) > 0) {
        const double alpha = (lu * ist + itt * lv) / det;
        const double beta = (-ist * lv - iss * lu) / det;
        for (const Vec2& c : s.corners) {
            const double sigma = axial + alpha * c.x + beta * c.y;
            lo = std::min(lo, sigma);
            hi = std::max(hi, sigma);
        }
    }
    for (const Vec2& c : s.corners)
        rmax = std::max(rmax, std::sqrt(c.x * c.x + c.y * c.y));
    const double torsion = dot(b.moment, s.normal);
    const Vec3 transverse = b.force - s.normal * dot(b.force, s.normal);
    const double polar = iss + itt;
    out.tension = std::max(0.0, hi) / b.health;
    out.compression = std::max(0.0, -lo) / b.health;
    out.shear =
        (length(transverse) / s.sectionArea + (polar > 0 ? std::abs(torsion) * rmax / polar : 0)) / b.health;
    return out;
}

void StressSolver::solveBearing(BondState& b) {
    const BondInterface& x = b.bond.section;
    NodeState& na = nodes_[b.bond.a];
    NodeState& nb = nodes_[b.bond.b];
    const Vec3 dir[3] = {x.normal, x.u, x.v};
    // The corner's relative velocity along dir[j], and an impulse l along dir[j] on a (-l on b), through the
    // corner's precomputed lever arms (no matrix products in the sweep).
    auto relative = [&](const BearingCorner& k, int j) {
        return dot(na.v - nb.v, dir[j]) + dot(na.w, k.ca[j]) - dot(nb.w, k.cb[j]);
    };
    auto push = [&](const BearingCorner& k, int j, double l) {
        na.v += dir[j] * (l * na.invMass);
        na.w += k.ia[j] * l;
        nb.v -= dir[j] * (l * nb.invMass);
        nb.w -= k.ib[j] * l;
    };
    for (BearingCorner& k : b.corners) {
        // a corner's force acts on a (its opposite on b): b pushing a away is -normal * press
        const double press = std::max(0.0, k.press + relative(k, 0) / k.kn);
        push(k, 0, -(press - k.press));
        k.press = press;
        double gu = k.gu - relative(k, 1) / k.ku, gv = k.gv - relative(k, 2) / k.kv;
        const double grip = b.limits.friction * k.press, g = std::sqrt(gu * gu + gv * gv);
        if (g > grip) {
            gu *= grip / g;
            gv *= grip / g;
        }
        push(k, 1, gu - k.gu);
        push(k, 2, gv - k.gv);
        k.gu = gu;
        k.gv = gv;
    }
}

void StressSolver::gatherBearing(BondState& b) {
    const BondInterface& x = b.bond.section;
    b.force = b.moment = Vec3{};
    for (const BearingCorner& k : b.corners) {
        const Vec3 f = x.normal * -k.press + x.u * k.gu + x.v * k.gv;
        b.force += f;
        b.moment += cross(k.offset, f);
    }
}

double StressSolver::bearingUtilisation(const BondState& b) const {
    const BondInterface& s = b.bond.section;
    auto plane = [&](const BearingCorner& k) { return Vec2{dot(k.offset, s.u), dot(k.offset, s.v)}; };
    double press = 0, gu = 0, gv = 0;
    Vec2 e{0, 0};
    for (const BearingCorner& k : b.corners) {
        const Vec2 c = plane(k);
        press += k.press;
        e.x += k.press * c.x;
        e.y += k.press * c.y;
        gu += k.gu;
        gv += k.gv;
    }
    if (press <= 0)
        return 0;
    e.x /= press;
    e.y /= press;
    double tip = 0; // the resultant against each hull edge (the corners run counter-clockwise): 1 on the edge
    const std::size_t n = b.corners.size();
    for (std::size_t k = 0; n >= 3 && k < n; ++k) {
        const Vec2 a = plane(b.corners[k]), c = plane(b.corners[(k + 1) % n]);
        const Vec2 m{c.y - a.y, a.x - c.x}; // outward
        const double h = m.x * a.x + m.y * a.y;
        if (h > 0)
            tip = std::max(tip, (m.x * e.x + m.y * e.y) / h);
    }
    const double slide = std::sqrt(gu * gu + gv * gv) / (b.limits.friction * press);
    const double crush = b.limits.compressive > 0 && s.sectionArea > 0
                             ? press / (s.sectionArea * b.health) / b.limits.compressive
                             : 0.0;
    return std::max({std::min(tip, 1.0), std::min(slide, 1.0), crush}); // only crushing exceeds 1
}

double StressSolver::utilisation(std::size_t i) const {
    if (bonds_[i].broken)
        return 0;
    if (bonds_[i].limits.friction > 0)
        return bearingUtilisation(bonds_[i]);
    const BondStress s = stress(i);
    const StrengthLimits& l = bonds_[i].limits;
    auto ratio = [](double stress, double limit) { return limit > 0 ? stress / limit : 0.0; };
    return std::max(
        {ratio(s.compression, l.compressive), ratio(s.tension, l.tensile), ratio(s.shear, l.shear)});
}

void StressSolver::damage(const Vec3& point, double radius, double amount) {
    for (std::size_t i = 0; i < bonds_.size(); ++i) {
        BondState& b = bonds_[i];
        const double d = length(b.bond.section.centroid - point);
        if (b.broken || d >= radius)
            continue;
        b.health -= amount * (1 - d / radius);
        if (b.health <= 0) {
            b.health = 0;
            breakBond(i);
        }
    }
}

std::vector<std::size_t> StressSolver::breakOverstressed() {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < bonds_.size(); ++i) {
        if (bonds_[i].broken)
            continue;
        if (utilisation(i) > 1)
            out.push_back(i);
    }
    for (std::size_t i : out)
        breakBond(i);
    return out;
}

void StressSolver::setHealth(std::size_t i, double health) {
    bonds_[i].health = std::clamp(health, 0.0, 1.0);
    if (bonds_[i].health <= 0)
        breakBond(i);
}

void StressSolver::breakBond(std::size_t i) {
    bonds_[i].broken = true;
    bonds_[i].force = bonds_[i].moment = Vec3{};
}

void StressSolver::detach(std::uint32_t node) {
    nodes_[node].detached = true;
    for (std::size_t i : nodes_[node].bonds)
        breakBond(i);
}

std::vector<std::uint32_t> StressSolver::unsupported() const {
    std::vector<char> reached(nodes_.size(), 0);
    std::deque<std::uint32_t> open;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
        if (nodes_[i].node.root && !nodes_[i].detached) {
            reached[i] = 1;
            open.push_back(i);
        }
    while (!open.empty()) {
        const std::uint32_t n = open.front();
        open.pop_front();
        for (std::size_t i : nodes_[n].bonds) {
            const BondState& b = bonds_[i];
            const std::uint32_t m = b.bond.other(n);
            if (!b.broken && !reached[m]) {
                reached[m] = 1;
                open.push_back(m);
            }
        }
    }
    std::vector<std::uint32_t> out;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
        if ((!reached[i] || nodes_[i].unbalanced >= settings_.unbalancedSolves) && !nodes_[i].detached)
            out.push_back(i);
    return out;
}

} // namespace rubble
