#include "rubble/structure/StressSolver.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#ifdef RUBBLE_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#include <dlfcn.h>
#endif
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <queue>
#include <tuple>

#include "rubble/geometry/MassProperties.hpp"

namespace rubble {

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;

// Direct: conjugate-gradient iterations a solve against changed numbers may take before a refactorisation.
constexpr int kUpdateIterations = 16;
// Direct: the fewest unknowns an island needs for such solves (below, refactorising costs less).
constexpr Eigen::Index kUpdateUnknowns = 2400;
// Direct: the most constraint rows an active-set change may add or remove as an up/down-date of the factor.
constexpr int kAmendRows = 48;

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

#ifdef RUBBLE_HAVE_CHOLMOD
// Keeps CHOLMOD's OpenMP regions on the calling thread while alive (Debian's CHOLMOD asks for 4 threads):
// the solver runs on the caller's thread only. Looked up at run time: OpenMP comes in with CHOLMOD.
class SerialOpenMp {
public:
    SerialOpenMp() {
        get_ = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
        set_ = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
        if (get_ && set_) {
            saved_ = get_();
            set_(0);
        }
    }
    ~SerialOpenMp() {
        if (get_ && set_)
            set_(saved_);
    }
    SerialOpenMp(const SerialOpenMp&) = delete;
    SerialOpenMp& operator=(const SerialOpenMp&) = delete;

private:
    int (*get_)() = nullptr;
    void (*set_)(int) = nullptr;
    int saved_ = 0;
};
// CHOLMOD's factorisation: supernodal LL' on large islands, simplicial LDL' on small ones, which an
// active-set change up- and down-dates (cholmod_updown) instead of refactorising.
class Factorization : public Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>> {
public:
    void small(bool simplicial) { setMode(simplicial ? Eigen::CholmodLDLt : Eigen::CholmodSupernodalLLt); }
    // Makes the factorisation that of A + C C' (up) or A - C C'; false when it cannot (then unusable).
    bool updown(bool up, const Eigen::SparseMatrix<double>& c) {
        cholmod_factor* l = m_cholmodFactor;
        if (!l || l->is_super || l->is_ll || c.cols() == 0)
            return l && !l->is_super && !l->is_ll;
        cholmod_sparse view = Eigen::viewAsCholmod(c);
        cholmod_sparse* permuted =
            cholmod_submatrix(&view, static_cast<int*>(l->Perm), static_cast<SuiteSparse_long>(l->n), nullptr,
                              -1, 1, 1, &cholmod());
        if (!permuted)
            return false;
        const int ok = cholmod_updown(up ? 1 : 0, permuted, l, &cholmod());
        cholmod_free_sparse(&permuted, &cholmod());
        return ok && l->minor == l->n;
    }
};
#else
struct SerialOpenMp {};
// Eigen's simplicial LDL' (no up/down-dates: an active-set change refactorises).
class Factorization : public Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> {
public:
    void small(bool) {}
    bool updown(bool, const Eigen::SparseMatrix<double>&) { return false; }
};
#endif

} // namespace

// One island's factorisation (the movable nodes that bonds join; a bond to a held node belongs to its movable
// end's island), kept across solves while the island's nodes, bonds and active set stay.
struct DirectIsland {
    std::vector<std::size_t> key; // its nodes in unknown order, then each bond's slot and nodes
    std::vector<char> flags;      // each corner's active and slip flags the factorisation holds
    Factorization ldlt;
    bool analysed = false;
    bool numeric = false;  // ldlt holds a numeric factorisation of this key's pattern
    bool factored = false; // ... of the nodes' and bonds' numbers, or `matrix` holds them (until one changes)
    bool drift = false;    // `matrix` holds them: bonds broke or corners changed since ldlt was made
    bool amended = false;  // ldlt was up- or down-dated to `assembled` since it was made (solves refined)
    double compliance = 0; // the one it was made with
    Eigen::SparseMatrix<double> matrix;
    Eigen::SparseMatrix<double> assembled; // the last matrix assembled (the nodes and bonds of assembledKey)
    std::vector<std::size_t> assembledKey;
    std::vector<std::array<int, 4>> places; // each bond's blocks' offsets in their columns' runs (-1: held)
};

// A bond's 12 x 12 block of J^T E^-1 J, kept while its lever arms, break state and corners' flags stay.
struct BondBlock {
    Eigen::Matrix<double, 12, 12> block;
    std::vector<char> flags; // each corner's active and slip flags it was made with
    double compliance = 0;   // 0: none made since the bond last changed
    bool broken = false;
};

// The direct solve's factorisations, one per island, and the nodes changed since the last solve.
struct StressSolver::DirectCache {
    std::map<std::uint32_t, std::unique_ptr<DirectIsland>> islands; // by the island's lowest node
    std::vector<char> touched;     // a node whose island's numbers changed (its bonds, its mass, its root)
    std::vector<BondBlock> blocks; // by bond slot
    bool polishing = false; // its Gauss-Seidel polish runs: stalls what stops converging (solveGaussSeidel)
    void touch(std::uint32_t node) {
        if (node >= touched.size())
            touched.resize(node + 1, 0);
        touched[node] = 1;
    }
    // The bond's lever arms or corners were made again (added, removed, a node's root changed).
    void forget(std::size_t bond) {
        if (bond < blocks.size())
            blocks[bond].compliance = 0;
    }
};

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
    dirty_.clear();
    orphans_.clear();
    fresh_.clear();
    breaks_.clear();
    direct_.reset();
    allDirty_ = true;
    reachValid_ = false;
    reachFull_ = true;
    bearingBonds_ = 0;
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
    reachValid_ = false;
    std::uint32_t i = static_cast<std::uint32_t>(nodes_.size());
    if (freeNodes_.empty()) {
        nodes_.push_back(std::move(s));
    } else {
        i = freeNodes_.back();
        freeNodes_.pop_back();
        nodes_[i] = std::move(s);
    }
    if (node.root)
        reachGained_.push_back(i);
    if (direct_)
        direct_->touch(i);
    return i;
}

void StressSolver::removeNode(std::uint32_t node) {
    NodeState& n = nodes_[node];
    if (n.removed)
        return;
    for (std::size_t k : n.bonds) {
        const BondState& b = bonds_[k];
        if (b.broken || !b.solvable)
            continue;
        const std::uint32_t m = b.bond.other(node);
        const double sign = b.bond.a == m ? 1.0 : -1.0;
        orphans_.push_back(
            {m, b.force * sign, b.moment * sign, b.bond.section.centroid, b.bond.section.normal});
    }
    std::erase_if(orphans_, [&](const Orphan& o) { return o.node == node; });
    for (std::size_t b : std::vector<std::size_t>(n.bonds))
        removeBond(b);
    n = NodeState{};
    n.removed = n.detached = true;
    reachValid_ = false;
    if (node < reached_.size())
        reached_[node] = 0;
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
    if (direct_)
        direct_->forget(i);
    bearingBonds_ += limits.friction > 0;
    for (std::uint32_t n : {bonds_[i].bond.a, bonds_[i].bond.b}) {
        std::vector<std::size_t>& list = nodes_[n].bonds;
        list.insert(std::upper_bound(list.begin(), list.end(), i), i);
        nodes_[n].bearings += limits.friction > 0;
        if (direct_)
            direct_->touch(n);
    }
    reachValid_ = false;
    reachGained_.push_back(bonds_[i].bond.a);
    reachGained_.push_back(bonds_[i].bond.b);
    if (!orphans_.empty())
        fresh_.push_back(i);
    return i;
}

void StressSolver::removeBond(std::size_t i) {
    BondState& b = bonds_[i];
    bearingBonds_ -= b.limits.friction > 0;
    for (std::uint32_t n : {b.bond.a, b.bond.b}) {
        std::erase(nodes_[n].bonds, i);
        nodes_[n].bearings -= b.limits.friction > 0;
        markDirty(n);
        if (direct_)
            direct_->touch(n);
        reachLost_.push_back(n);
    }
    reachValid_ = false;
    if (direct_)
        direct_->forget(i);
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
    markDirty(node);
    if (direct_)
        direct_->touch(node);
    for (std::size_t i : n.bonds) {
        prepare(bonds_[i]);
        markDirty(bonds_[i].bond.other(node));
        if (direct_) {
            direct_->touch(bonds_[i].bond.other(node));
            direct_->forget(i);
        }
    }
    reachValid_ = false;
    reachFull_ = true;
}

void StressSolver::markDirty(std::uint32_t node) {
    if (!nodes_[node].dirty) {
        nodes_[node].dirty = true;
        dirty_.push_back(node);
    }
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

// Bonds added across the faces of removed bonds take their loads, split by area (a warm start: the solve
// corrects it).
void StressSolver::inherit() {
    for (const Orphan& o : orphans_) {
        std::vector<std::size_t> heirs;
        double area = 0;
        for (std::size_t k : fresh_) {
            const BondState& b = bonds_[k];
            if (!b.removed && !b.broken && b.solvable && (b.bond.a == o.node || b.bond.b == o.node) &&
                std::abs(dot(b.bond.section.normal, o.normal)) > 0.99) {
                heirs.push_back(k);
                area += b.bond.section.sectionArea;
            }
        }
        for (std::size_t k : heirs) {
            BondState& b = bonds_[k];
            const double share = area > 0 ? b.bond.section.sectionArea / area : 0.0;
            const Vec3 force = o.force * share;
            const Vec3 moment = (o.moment + cross(o.centroid - b.bond.section.centroid, o.force)) * share;
            const double sign = b.bond.a == o.node ? 1.0 : -1.0;
            b.force += force * sign;
            b.moment += moment * sign;
            for (BearingCorner& c : b.corners) // a bearing: its push, shared by the corners
                c.press = std::max(0.0, -dot(b.force, b.bond.section.normal)) /
                          static_cast<double>(b.corners.size());
            if (!b.corners.empty())
                gatherBearing(b);
            markDirty(b.bond.a);
            markDirty(b.bond.b);
        }
    }
    orphans_.clear();
    fresh_.clear();
}

// A structure whose bonds carry nothing yet (just built) starts from its dead load passed down: from the
// highest node to the lowest, each node's weight and what rests on it goes to the bonds under it, by
// horizontal section area (a warm start: the solve corrects it).
void StressSolver::coldStart() {
    for (const BondState& b : bonds_)
        if (!b.broken && (lengthSquared(b.force) > 0 || lengthSquared(b.moment) > 0))
            return;
    const double g = length(settings_.gravity);
    if (g <= 0)
        return;
    const Vec3 down = settings_.gravity / g;
    std::vector<std::uint32_t> order;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
        if (movable(i))
            order.push_back(i);
    auto height = [&](std::uint32_t i) { return -dot(nodes_[i].node.centroid, down); };
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t x, std::uint32_t y) { return height(x) > height(y); });
    std::vector<double> load(nodes_.size(), 0);
    for (std::uint32_t i : order) {
        const NodeState& n = nodes_[i];
        const double total = load[i] + n.node.mass * g + std::max(0.0, dot(n.force, down));
        double area = 0;
        auto under = [&](const BondState& b) {
            const BondInterface& x = b.bond.section;
            return !b.broken && b.solvable && std::abs(dot(x.normal, down)) > 0.5 &&
                   dot(x.centroid - n.node.centroid, down) > 0;
        };
        for (std::size_t k : n.bonds)
            if (under(bonds_[k]))
                area +=
                    bonds_[k].bond.section.sectionArea * std::abs(dot(bonds_[k].bond.section.normal, down));
        if (area <= 0)
            continue;
        for (std::size_t k : n.bonds) {
            BondState& b = bonds_[k];
            if (!under(b))
                continue;
            const double share =
                total * b.bond.section.sectionArea * std::abs(dot(b.bond.section.normal, down)) / area;
            const std::uint32_t j = b.bond.other(i);
            if (movable(j))
                load[j] += share;
            b.force = down * (b.bond.a == i ? -share : share); // up on the node above
            for (BearingCorner& c : b.corners)
                c.press = share / static_cast<double>(b.corners.size());
        }
    }
    allDirty_ = true;
}

void StressSolver::solve() {
    method_ = settings_.method != StressMethod::Auto ? settings_.method
              : bearingBonds_ > 0                    ? StressMethod::Direct
                                                     : StressMethod::GaussSeidel;
    // Nodes that replace a removed one (a fracture's pieces): with routeLoads they first balance among
    // themselves, below.
    std::vector<std::uint32_t> newcomers;
    const bool routing = settings_.routeLoads && method_ != StressMethod::SweepBudget && !allDirty_;
    if (routing)
        for (std::size_t k : fresh_)
            for (std::uint32_t n : {bonds_[k].bond.a, bonds_[k].bond.b})
                if (!nodes_[n].solved && !nodes_[n].removed)
                    newcomers.push_back(n);
    std::sort(newcomers.begin(), newcomers.end());
    newcomers.erase(std::unique(newcomers.begin(), newcomers.end()), newcomers.end());
    if (!orphans_.empty())
        inherit();
    fresh_.clear();
    if (method_ != StressMethod::SweepBudget && settings_.deadLoadGuess && allDirty_) {
        if (!reachValid_)
            reach();
        coldStart();
    }
    const double scale = startSolve();
    scale_ = scale;
    history_.clear();
    if (!routes_.empty() && method_ != StressMethod::Direct)
        route(routes_);
    if (!newcomers.empty() && method_ != StressMethod::Direct)
        settleAmong(newcomers, settings_.residual * scale);
    if (routing && method_ != StressMethod::Direct) // what is still unbalanced goes down, if it can
        routeUnbalanced(settings_.residual * scale);
    factorizations_ = blocksMade_ = 0;
    switch (method_) {
    case StressMethod::Auto: // resolved above
    case StressMethod::SweepBudget:
        solveSweepBudget();
        break;
    case StressMethod::GaussSeidel:
        solveGaussSeidel(settings_.residual * scale);
        break;
    case StressMethod::ConjugateGradient:
        solveConjugateGradient(settings_.residual * scale);
        break;
    case StressMethod::Direct:
        solveDirect(settings_.residual * scale);
        break;
    }
    finishSolve(scale);
}

bool StressSolver::movable(std::uint32_t i) const {
    const NodeState& n = nodes_[i];
    return reached_[i] && n.invMass > 0 && !n.detached && !n.stalled;
}

// The squared size of a node's acceleration (v, w) in the mass metric: |v|^2 + w.I w / m, in (m/s^2)^2.
double StressSolver::nodeResidual(const NodeState& n) const {
    return lengthSquared(n.v) + dot(n.w, n.node.inertia * n.w) * n.invMass;
}

// Unit time step: velocity changes are accelerations and accumulated impulses are forces. Each node's v and w
// hold its acceleration under its loads and the bonds' forces between solves; this frame's loads replace the
// last's, and nodes whose bonds changed are summed again. Returns the largest acceleration the loads alone
// give a supported node (the residual's scale).
double StressSolver::startSolve() {
    if (!(settings_.gravity == gravity_))
        allDirty_ = true;
    gravity_ = settings_.gravity;
    if (!reachValid_)
        reach();
    const bool routing = settings_.routeLoads && method_ != StressMethod::SweepBudget && !allDirty_;
    routes_.clear();
    double scale2 = 0;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i) {
        NodeState& n = nodes_[i];
        n.stalled = false;
        Vec3 fv, fw;
        if (n.invMass > 0 && !n.detached) {
            fv = settings_.gravity + n.force * n.invMass;
            fw = n.invInertia * n.torque;
        }
        if (routing && n.solved && movable(i) && !(fv == n.fv && fw == n.fw))
            routes_.push_back({i, (fv - n.fv) * n.node.mass, n.node.inertia * (fw - n.fw)});
        n.solved = true;
        n.force = n.torque = Vec3{};
        if (allDirty_ || n.dirty) {
            n.v = fv;
            n.w = fw;
            n.dirty = false;
            for (std::size_t k : n.bonds) {
                const BondState& b = bonds_[k];
                if (b.broken || !b.solvable || n.invMass <= 0 || n.detached)
                    continue;
                const double sign = b.bond.a == i ? 1.0 : -1.0;
                n.v += b.force * (sign * n.invMass);
                n.w += n.invInertia * ((cross(b.bond.a == i ? b.ra : b.rb, b.force) + b.moment) * sign);
            }
        } else {
            n.v += fv - n.fv;
            n.w += fw - n.fw;
        }
        n.fv = fv;
        n.fw = fw;
        if (movable(i))
            scale2 = std::max(scale2, lengthSquared(fv) + dot(fw, n.node.inertia * fw) * n.invMass);
    }
    dirty_.clear();
    allDirty_ = false;
    return std::sqrt(scale2);
}

// Load changes passed down to the ground, highest node first: each node's change goes to the welds beneath it
// (section below its centroid, facing within 60 degrees of gravity, to a lower node or a held one), split by
// their horizontal section area, each weld taking its share of the force and of the moment about its own
// centroid, so the node stays balanced; the node below takes the reaction as its own change. Exact for welds;
// what has no weld beneath (a cantilever's tip, a body on bearings) keeps its change for the iteration.
void StressSolver::route(std::vector<Route>& changes) {
    const double g = length(settings_.gravity);
    if (g <= 0)
        return;
    const Vec3 down = settings_.gravity / g;
    auto height = [&](std::uint32_t i) { return -dot(nodes_[i].node.centroid, down); };
    std::map<std::pair<double, std::uint32_t>, std::pair<Vec3, Vec3>, std::greater<>> open;
    for (const Route& r : changes) {
        auto& e = open[{height(r.node), r.node}];
        e.first += r.force;
        e.second += r.torque;
    }
    changes.clear();
    std::vector<std::pair<std::size_t, double>> below;
    while (!open.empty()) {
        const auto [key, load] = *open.begin();
        open.erase(open.begin());
        const std::uint32_t i = key.second;
        const NodeState& n = nodes_[i];
        below.clear();
        double area = 0;
        for (const bool steep : {false, true}) { // welds facing down first, else any weld to a lower node
            for (std::size_t k : n.bonds) {
                if (!weldBeneath(k, i, down, steep))
                    continue;
                const BondInterface& x = bonds_[k].bond.section;
                below.push_back({k, steep ? x.sectionArea : x.sectionArea * std::abs(dot(x.normal, down))});
                area += below.back().second;
            }
            if (area > 0)
                break;
        }
        if (area <= 0)
            continue;
        const auto& [force, torque] = load;
        for (const auto& [k, a] : below) {
            BondState& b = bonds_[k];
            const double share = a / area;
            const Vec3 arm = b.bond.section.centroid - n.node.centroid;
            const Vec3 f = force * -share;                        // on node i, from the node beneath
            const Vec3 m = (torque - cross(arm, force)) * -share; // about the section centroid
            const double sign = b.bond.a == i ? 1.0 : -1.0;
            b.force += f * sign;
            b.moment += m * sign;
            apply(b, f * sign, m * sign);
            const std::uint32_t j = b.bond.other(i);
            if (movable(j)) {
                auto& e = open[{height(j), j}];
                e.first += force * share;
                e.second += cross(b.bond.section.centroid - nodes_[j].node.centroid, force * share) - m;
            }
        }
    }
}

// Bond k of node n is a weld to a lower or held node, facing down from below n (any such weld when steep).
bool StressSolver::weldBeneath(std::size_t k, std::uint32_t n, const Vec3& down, bool steep) const {
    const BondState& b = bonds_[k];
    if (!b.intactWeld())
        return false;
    const std::uint32_t m = b.bond.other(n);
    const Vec3& c = nodes_[n].node.centroid;
    if (movable(m) && -dot(nodes_[m].node.centroid, down) >= -dot(c, down)) // not lower
        return false;
    const BondInterface& x = b.bond.section;
    return steep || (std::abs(dot(x.normal, down)) > 0.5 && dot(x.centroid - c, down) > 0);
}

// A node's imbalance as a load change to route: (m v, I w).
StressSolver::Route StressSolver::unbalance(std::uint32_t n) const {
    const NodeState& s = nodes_[n];
    return {n, s.v * s.node.mass, s.node.inertia * s.w};
}

// Passes every node still out of the tolerance down its welds, else balances it with rings of neighbours.
void StressSolver::routeUnbalanced(double tolerance) {
    std::vector<Route> rest;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
        if (movable(i) && nodeResidual(nodes_[i]) > tolerance * tolerance)
            rest.push_back(unbalance(i));
    if (rest.empty())
        return;
    std::vector<std::uint32_t> routed;
    for (const Route& r : rest)
        routed.push_back(r.node);
    route(rest);
    // What routing could not pass down (no weld to a lower node) is balanced with its welded neighbours.
    constexpr std::size_t kMostRings = 64;
    std::size_t rings = 0;
    for (const std::uint32_t n : routed) {
        if (rings == kMostRings)
            break;
        // the node and its welded neighbours, one ring more while that leaves it unbalanced (three at most)
        std::vector<std::uint32_t> ring{n};
        for (int radius = 1; radius <= 3; ++radius) {
            if (!movable(n) || nodeResidual(nodes_[n]) <= tolerance * tolerance)
                break;
            const std::size_t last = ring.size();
            for (std::size_t i = 0; i < last; ++i)
                for (std::size_t k : nodes_[ring[i]].bonds) {
                    const BondState& b = bonds_[k];
                    const std::uint32_t m = b.bond.other(ring[i]);
                    if (b.intactWeld() && movable(m))
                        ring.push_back(m);
                }
            std::sort(ring.begin(), ring.end());
            ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
            (void)balanceDown(ring);
            ++rings;
        }
    }
}

// Balances a welded group over its welds and those beneath it, routing the reactions down; its inner bonds.
std::vector<std::size_t> StressSolver::balanceDown(const std::vector<std::uint32_t>& group) {
    std::vector<std::size_t> inside;
    for (std::uint32_t n : group)
        for (std::size_t k : nodes_[n].bonds) {
            const BondState& b = bonds_[k];
            const std::uint32_t m = b.bond.other(n);
            if (n < m && !b.broken && b.solvable && std::binary_search(group.begin(), group.end(), m) &&
                (movable(n) || movable(m)))
                inside.push_back(k);
        }
    std::sort(inside.begin(), inside.end());
    if (!std::all_of(inside.begin(), inside.end(), [&](std::size_t k) { return bonds_[k].corners.empty(); }))
        return inside;
    const double g = length(settings_.gravity);
    const Vec3 down = g > 0 ? settings_.gravity / g : Vec3{};
    std::vector<std::size_t> welds = inside;
    std::vector<std::uint32_t> below;
    for (const bool steep : {false, true}) { // welds facing down first, else any weld to a lower node
        for (std::uint32_t n : group)
            for (std::size_t k : nodes_[n].bonds) {
                const std::uint32_t m = bonds_[k].bond.other(n);
                if (!movable(n) || std::binary_search(group.begin(), group.end(), m) ||
                    !weldBeneath(k, n, down, steep))
                    continue;
                welds.push_back(k);
                if (movable(m))
                    below.push_back(m);
            }
        if (welds.size() > inside.size())
            break;
    }
    if (!balanceAmong(group, welds))
        return inside;
    std::sort(below.begin(), below.end());
    below.erase(std::unique(below.begin(), below.end()), below.end());
    std::vector<Route> rest;
    for (std::uint32_t n : below)
        rest.push_back(unbalance(n));
    route(rest);
    return inside;
}

// A fracture's pieces balanced down (balanceDown), then Gauss-Seidel among them for what that left.
void StressSolver::settleAmong(const std::vector<std::uint32_t>& group, double tolerance) {
    const std::vector<std::size_t> inside = balanceDown(group);
    auto worst = [&] {
        double m = 0;
        for (std::uint32_t n : group)
            if (movable(n))
                m = std::max(m, nodeResidual(nodes_[n]));
        return m;
    };
    double last = worst();
    for (int sweep = 1; sweep <= 400 && last > tolerance * tolerance; ++sweep) {
        for (std::size_t k : inside) {
            if (!bonds_[k].corners.empty())
                solveBearing(bonds_[k]);
            else
                solveWeld(bonds_[k]);
        }
        if (sweep % 10 == 0) { // stop once ten sweeps gain less than 10 %
            const double now = worst();
            if (now > 0.81 * last)
                break;
            last = now;
        }
    }
}

// The least change of these welds' forces that leaves the group at rest (docs/structure.md); false if none.
bool StressSolver::balanceAmong(const std::vector<std::uint32_t>& group,
                                const std::vector<std::size_t>& welds) {
    constexpr std::size_t kMostNodes = 48;
    std::vector<int> local(group.size(), -1);
    int n = 0;
    for (std::size_t i = 0; i < group.size(); ++i)
        if (movable(group[i]))
            local[i] = n++;
    if (n == 0 || welds.empty() || static_cast<std::size_t>(n) > kMostNodes)
        return false;
    auto indexOf = [&](std::uint32_t node) {
        const auto it = std::lower_bound(group.begin(), group.end(), node);
        return it != group.end() && *it == node ? local[static_cast<std::size_t>(it - group.begin())] : -1;
    };
    // Columns of J^T: a weld's (F, M) acts on a as (F, ra x F + M) and on b as the negative with rb.
    const Eigen::Index rows = 6 * n, cols = 6 * static_cast<Eigen::Index>(welds.size());
    Eigen::MatrixXd jt = Eigen::MatrixXd::Zero(rows, cols);
    for (std::size_t k = 0; k < welds.size(); ++k) {
        const BondState& b = bonds_[welds[k]];
        for (const auto& [node, r, sign] :
             {std::tuple{b.bond.a, b.ra, 1.0}, std::tuple{b.bond.b, b.rb, -1.0}}) {
            const int i = indexOf(node);
            if (i < 0)
                continue;
            auto block = jt.block<6, 6>(6 * i, 6 * static_cast<Eigen::Index>(k));
            block.setIdentity();
            const Eigen::Matrix3d skew{{0, -r.z, r.y}, {r.z, 0, -r.x}, {-r.y, r.x, 0}};
            block.block<3, 3>(3, 0) = skew;
            block *= sign;
        }
    }
    // The generalised force that brings each node to rest: -(m v, I w).
    Eigen::VectorXd f(rows);
    for (std::size_t i = 0; i < group.size(); ++i) {
        if (local[i] < 0)
            continue;
        const NodeState& s = nodes_[group[i]];
        const Vec3 lin = s.v * -s.node.mass, ang = s.node.inertia * s.w * -1.0;
        f.segment<6>(6 * local[i]) << lin.x, lin.y, lin.z, ang.x, ang.y, ang.z;
    }
    // The least change: the minimum-norm least-squares solution of J^T change = f.
    const Eigen::VectorXd change = jt.completeOrthogonalDecomposition().solve(f);
    if (!change.allFinite())
        return false;
    for (std::size_t k2 = 0; k2 < welds.size(); ++k2) {
        const auto c = change.segment<6>(6 * static_cast<Eigen::Index>(k2));
        BondState& b = bonds_[welds[k2]];
        const Vec3 df{c[0], c[1], c[2]}, dm{c[3], c[4], c[5]};
        b.force += df;
        b.moment += dm;
        apply(b, df, dm);
    }
    return true;
}

// The nodes a chain of intact bonds links to a root (kept until a bond or root changes).
void StressSolver::reach() {
    if (reachFull_ || !reachAgain())
        reached_ = reachable();
    reachValid_ = true;
    reachFull_ = false;
    reachLost_.clear();
    reachGained_.clear();
}

// reached_ updated from the bonds lost and gained (docs/structure.md); false to find it again whole.
bool StressSolver::reachAgain() {
    reached_.resize(nodes_.size(), 0);
    const std::size_t most = std::max<std::size_t>(512, nodes_.size() / 8);
    const double g = length(settings_.gravity);
    const Vec3 down = g > 0 ? settings_.gravity / g : Vec3{0, -1, 0};
    std::vector<char> held(nodes_.size(), 0);          // proven linked to a root in this call
    std::vector<std::uint32_t> seen(nodes_.size(), 0); // the search that met the node (1, 2, ...)
    std::uint32_t search = 0;
    std::vector<std::uint32_t> met;
    using Open = std::pair<double, std::uint32_t>; // (height, node): lowest first
    std::priority_queue<Open, std::vector<Open>, std::greater<>> open;
    auto root = [&](std::uint32_t i) { return nodes_[i].node.root && !nodes_[i].detached; };
    for (std::uint32_t start : reachLost_) {
        if (start >= nodes_.size() || nodes_[start].removed || !reached_[start] || held[start])
            continue;
        met.assign(1, start);
        open = {};
        open.push({-dot(nodes_[start].node.centroid, down), start});
        seen[start] = ++search;
        bool linked = false;
        while (!open.empty() && !linked) {
            const std::uint32_t n = open.top().second;
            open.pop();
            if (root(n) || held[n]) {
                linked = true;
                break;
            }
            for (std::size_t k : nodes_[n].bonds) {
                const BondState& b = bonds_[k];
                const std::uint32_t m = b.bond.other(n);
                if (b.broken || seen[m] == search)
                    continue;
                seen[m] = search;
                met.push_back(m);
                open.push({-dot(nodes_[m].node.centroid, down), m});
            }
            if (met.size() > most)
                return false;
        }
        for (std::uint32_t m : met) {
            if (linked)
                held[m] = 1; // met on the way to a root: linked too (its component holds the root)
            else
                reached_[m] = 0;
        }
    }
    std::vector<std::uint32_t> gained;
    for (std::uint32_t start : reachGained_)
        if (start < nodes_.size() && !nodes_[start].removed && (reached_[start] || root(start))) {
            reached_[start] = 1;
            gained.push_back(start);
        }
    spread(reached_, gained);
    return true;
}

// Marks everything a chain of intact bonds links to the open (marked) nodes.
void StressSolver::spread(std::vector<char>& reached, std::vector<std::uint32_t>& open) const {
    while (!open.empty()) {
        const std::uint32_t n = open.back();
        open.pop_back();
        for (std::size_t i : nodes_[n].bonds) {
            const BondState& b = bonds_[i];
            const std::uint32_t m = b.bond.other(n);
            if (!b.broken && !reached[m]) {
                reached[m] = 1;
                open.push_back(m);
            }
        }
    }
}

std::vector<char> StressSolver::reachable() const {
    std::vector<char> reached(nodes_.size(), 0);
    std::vector<std::uint32_t> open;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
        if (nodes_[i].node.root && !nodes_[i].detached) {
            reached[i] = 1;
            open.push_back(i);
        }
    spread(reached, open);
    return reached;
}

void StressSolver::solveWeld(BondState& b) {
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

void StressSolver::solveSweepBudget() {
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
    for (sweeps_ = 0; sweeps_ < settings_.iterations && !converged(); ++sweeps_) {
        for (BondState& b : bonds_) {
            if (b.broken || !b.solvable || (resting(nodes_[b.bond.a]) && resting(nodes_[b.bond.b])))
                continue;
            if (!b.corners.empty())
                solveBearing(b);
            else
                solveWeld(b);
        }
        traceSweep();
    }
}

// Gauss-Seidel over a work list: each sweep visits, in ascending order, the bonds of the nodes whose
// acceleration exceeds a quarter of the tolerance, until none exceeds the tolerance. A structure that did not
// change costs one pass over its nodes; a local change, sweeps over its neighbourhood.
void StressSolver::solveGaussSeidel(double tolerance) {
    const double tolerance2 = tolerance * tolerance, quiet2 = tolerance2 * 1e-4;
    std::vector<std::uint32_t> active, touched;
    std::vector<std::size_t> list;
    // The direct solve's polish checks every stallSweeps / 4 sweeps for what the last solve left unbalanced
    // and still moves; and every stallSweeps, a node on bearings still outside the tolerance whose
    // acceleration changed by at most 1 % since the last such check is stalled (the sweeps no longer move
    // it), whatever the last solve said and however small its acceleration.
    const bool polish = direct_ && direct_->polishing;
    std::vector<double> seen(polish ? nodes_.size() : 0, 0.0); // each node's residual at the last check
    double max2 = 0;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
        if (movable(i)) {
            const double e2 = nodeResidual(nodes_[i]);
            max2 = std::max(max2, e2);
            if (e2 > quiet2)
                active.push_back(i);
            if (polish)
                seen[i] = e2;
        }
    bondStamp_.resize(bonds_.size(), 0);
    nodeStamp_.resize(nodes_.size(), 0);
    auto resting = [&](std::uint32_t i) { return !movable(i) || nodeResidual(nodes_[i]) <= quiet2; };
    const double unbalanced2 = settings_.unbalanced * settings_.unbalanced;
    for (sweeps_ = 0; sweeps_ < settings_.maxSweeps && max2 > tolerance2; ++sweeps_) {
        const int stall = settings_.stallSweeps;
        const int every = polish ? std::max(1, stall / 4) : stall;
        if (sweeps_ > 0 && stall > 0 && (sweeps_ == stall || (polish && sweeps_ % every == 0))) {
            // What bearings did not hold in the last solve and still do not is left out: its bonds keep
            // their forces, it counts as unbalanced again, and the rest converges around it.
            for (std::uint32_t n : active) {
                NodeState& s = nodes_[n];
                bool stuck = false;
                if (polish && sweeps_ % stall == 0) { // stuck: unchanged within 1 % over stallSweeps
                    const double e = std::sqrt(nodeResidual(s)), last = std::sqrt(seen[n]);
                    stuck = last > 0 && e * e > tolerance2 && std::abs(e - last) <= 0.01 * last;
                    seen[n] = e * e;
                }
                const bool moving = lengthSquared(s.v) > unbalanced2 || lengthSquared(s.w) > unbalanced2;
                s.stalled = s.bearings > 0 && ((s.unbalanced > 0 && moving) || stuck);
            }
            std::erase_if(active, [&](std::uint32_t n) { return nodes_[n].stalled; });
            max2 = 0;
            for (std::uint32_t n : active)
                max2 = std::max(max2, nodeResidual(nodes_[n]));
            if (max2 <= tolerance2)
                break;
        }
        if (++stampNow_ == 0) {
            std::fill(bondStamp_.begin(), bondStamp_.end(), 0);
            std::fill(nodeStamp_.begin(), nodeStamp_.end(), 0);
            stampNow_ = 1;
        }
        list.clear();
        for (std::uint32_t n : active)
            for (std::size_t k : nodes_[n].bonds)
                if (!bonds_[k].broken && bonds_[k].solvable && bondStamp_[k] != stampNow_ &&
                    !nodes_[bonds_[k].bond.a].stalled && !nodes_[bonds_[k].bond.b].stalled) {
                    bondStamp_[k] = stampNow_;
                    list.push_back(k);
                }
        std::sort(list.begin(), list.end());
        touched.clear();
        for (std::size_t k : list) {
            BondState& b = bonds_[k];
            if (resting(b.bond.a) && resting(b.bond.b))
                continue;
            if (!b.corners.empty())
                solveBearing(b);
            else
                solveWeld(b);
            for (std::uint32_t n : {b.bond.a, b.bond.b})
                if (nodeStamp_[n] != stampNow_) {
                    nodeStamp_[n] = stampNow_;
                    touched.push_back(n);
                }
        }
        std::sort(touched.begin(), touched.end());
        active.clear();
        max2 = 0;
        for (std::uint32_t n : touched)
            if (movable(n)) {
                const double e2 = nodeResidual(nodes_[n]);
                max2 = std::max(max2, e2);
                if (e2 > quiet2)
                    active.push_back(n);
            }
        traceSweep();
    }
}

// With StressSettings::trace, the relative residual after this sweep.
void StressSolver::traceSweep() {
    if (!settings_.trace)
        return;
    double max2 = 0;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
        if (movable(i))
            max2 = std::max(max2, nodeResidual(nodes_[i]));
    history_.push_back(scale_ > 0 ? std::sqrt(max2) / scale_ : 0.0);
}

// Block-Jacobi preconditioned conjugate gradient on the welds' impulses (the system J M^-1 J^T l = -J v, the
// preconditioner each weld's own 6x6 block, as Gauss-Seidel uses), restarted after a projected sweep over the
// bearings every 16 iterations when there are any.
void StressSolver::solveConjugateGradient(double tolerance) {
    const double tolerance2 = tolerance * tolerance;
    using Block = std::array<double, 6>;
    std::vector<std::size_t> welds, bearings;
    for (std::size_t k = 0; k < bonds_.size(); ++k) {
        const BondState& b = bonds_[k];
        if (b.broken || !b.solvable || (!movable(b.bond.a) && !movable(b.bond.b)))
            continue;
        (b.corners.empty() ? welds : bearings).push_back(k);
    }
    std::vector<Block> r(welds.size()), z(welds.size()), p(welds.size()), q(welds.size());
    std::vector<Vec3> tv(nodes_.size()), tw(nodes_.size());
    auto relative = [&](const BondState& b, const Vec3& va, const Vec3& wa, const Vec3& vb, const Vec3& wb) {
        const Vec3 lin = (va + cross(wa, b.ra)) - (vb + cross(wb, b.rb)), ang = wa - wb;
        return Block{lin.x, lin.y, lin.z, ang.x, ang.y, ang.z};
    };
    auto precondition = [&](const BondState& b, const Block& in, Block& out) {
        for (int i = 0; i < 6; ++i) {
            double sum = 0;
            for (int c = 0; c < 6; ++c)
                sum += b.kinv[i * 6 + c] * in[c];
            out[i] = sum;
        }
    };
    auto dot6 = [](const Block& a, const Block& b) {
        double s = 0;
        for (int i = 0; i < 6; ++i)
            s += a[i] * b[i];
        return s;
    };
    auto maxResidual2 = [&] {
        double m = 0;
        for (std::uint32_t i = 0; i < nodes_.size(); ++i)
            if (movable(i))
                m = std::max(m, nodeResidual(nodes_[i]));
        return m;
    };
    double rz = 0;
    auto restart = [&] {
        rz = 0;
        for (std::size_t j = 0; j < welds.size(); ++j) {
            const BondState& b = bonds_[welds[j]];
            const NodeState &na = nodes_[b.bond.a], &nb = nodes_[b.bond.b];
            r[j] = relative(b, na.v, na.w, nb.v, nb.w);
            for (double& x : r[j])
                x = -x;
            precondition(b, r[j], z[j]);
            p[j] = z[j];
            rz += dot6(r[j], z[j]);
        }
    };
    restart();
    for (sweeps_ = 0; sweeps_ < settings_.maxSweeps && maxResidual2() > tolerance2; ++sweeps_) {
        if (!bearings.empty() && (sweeps_ % 16 == 15 || rz <= 0)) {
            for (std::size_t k : bearings)
                solveBearing(bonds_[k]);
            restart();
            traceSweep();
            continue;
        }
        if (rz <= 0)
            break;
        std::fill(tv.begin(), tv.end(), Vec3{});
        std::fill(tw.begin(), tw.end(), Vec3{});
        for (std::size_t j = 0; j < welds.size(); ++j) {
            const BondState& b = bonds_[welds[j]];
            const Vec3 f{p[j][0], p[j][1], p[j][2]}, m{p[j][3], p[j][4], p[j][5]};
            const NodeState &na = nodes_[b.bond.a], &nb = nodes_[b.bond.b];
            tv[b.bond.a] += f * na.invMass;
            tw[b.bond.a] += na.invInertia * (cross(b.ra, f) + m);
            tv[b.bond.b] -= f * nb.invMass;
            tw[b.bond.b] -= nb.invInertia * (cross(b.rb, f) + m);
        }
        double pq = 0;
        for (std::size_t j = 0; j < welds.size(); ++j) {
            const BondState& b = bonds_[welds[j]];
            q[j] = relative(b, tv[b.bond.a], tw[b.bond.a], tv[b.bond.b], tw[b.bond.b]);
            pq += dot6(p[j], q[j]);
        }
        if (pq <= 0)
            break;
        const double alpha = rz / pq;
        double rzNext = 0;
        for (std::size_t j = 0; j < welds.size(); ++j) {
            BondState& b = bonds_[welds[j]];
            b.force += Vec3{p[j][0], p[j][1], p[j][2]} * alpha;
            b.moment += Vec3{p[j][3], p[j][4], p[j][5]} * alpha;
            for (int i = 0; i < 6; ++i)
                r[j][i] -= alpha * q[j][i];
            precondition(b, r[j], z[j]);
            rzNext += dot6(r[j], z[j]);
        }
        for (std::uint32_t i = 0; i < nodes_.size(); ++i) {
            nodes_[i].v += tv[i] * alpha;
            nodes_[i].w += tw[i] * alpha;
        }
        const double beta = rzNext / rz;
        rz = rzNext;
        for (std::size_t j = 0; j < welds.size(); ++j)
            for (int i = 0; i < 6; ++i)
                p[j][i] = z[j][i] + beta * p[j][i];
        traceSweep();
    }
}

// The regularised bond system in node unknowns: the new accelerations a' of the movable nodes minimise
// (a' - a)^T M (a' - a) + sum over held constraints (J a')^2 / e, e = compliance times the constraint's own
// inverse effective mass, so (M + J^T E^-1 J) a' = M a, and the constraint forces change by -E^-1 J a'
// (augmented Lagrangian: repeated, the forces converge to J a = 0 from the warm start). A bearing's corners
// are held (normal and friction, sticking); a corner pulling leaves the set, one penetrating rejoins it and
// one sticking past friction slips (its friction a force at the limit from then on), each change a numeric
// refactorisation of the same pattern or, on a small island, an up/down-date of the factor (at most three
// a solve). The set and the factorisation are kept across solves until a node, bond or corner changes.
// Gauss-Seidel then meets the residual.
void StressSolver::solveDirect(double tolerance) {
    using Vec6 = Eigen::Matrix<double, 6, 1>;
    using Sparse = Eigen::SparseMatrix<double>;
    const double delta = std::max(settings_.compliance, 1e-12);
    [[maybe_unused]] const SerialOpenMp serial;
    if (!direct_ || direct_.use_count() > 1)
        direct_ = std::make_shared<DirectCache>();
    DirectCache& caches = *direct_;
    double start = 0;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
        if (movable(i))
            start = std::max(start, nodeResidual(nodes_[i]));
    if (start <= tolerance * tolerance) { // nothing to solve (an unchanged structure)
        solveGaussSeidel(tolerance);
        return;
    }
    // Islands: the movable nodes that bonds join (broken ones too, as they stay in the pattern), each with
    // its own factorisation; a change in one leaves the others' untouched.
    std::vector<int> index(nodes_.size(), -1); // a movable node's place in its island's unknowns
    std::vector<std::vector<std::uint32_t>> islands;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i) {
        if (!movable(i) || index[i] >= 0)
            continue;
        std::vector<std::uint32_t> members{i};
        index[i] = 0;
        for (std::size_t open = 0; open < members.size(); ++open)
            for (std::size_t k : nodes_[members[open]].bonds) {
                const BondState& b = bonds_[k];
                const std::uint32_t m = b.bond.other(members[open]);
                if (!b.removed && b.solvable && movable(m) && index[m] < 0) {
                    index[m] = 0;
                    members.push_back(m);
                }
            }
        std::sort(members.begin(), members.end());
        for (std::size_t j = 0; j < members.size(); ++j)
            index[members[j]] = static_cast<int>(j);
        islands.push_back(std::move(members));
    }
    std::vector<std::vector<std::size_t>> keys(islands.size()), patterns(islands.size());
    std::vector<std::unique_ptr<DirectIsland>> found(islands.size());
    for (std::size_t c = 0; c < islands.size(); ++c) {
        const std::vector<std::uint32_t>& members = islands[c];
        std::vector<std::size_t>& bonds = patterns[c];
        for (std::uint32_t i : members)
            for (std::size_t k : nodes_[i].bonds)
                if (!bonds_[k].removed && bonds_[k].solvable &&
                    (bonds_[k].bond.a == i || index[bonds_[k].bond.a] < 0))
                    bonds.push_back(k); // once: at its lower movable end
        std::sort(bonds.begin(), bonds.end());
        std::vector<std::size_t>& key = keys[c];
        key.assign(members.begin(), members.end());
        key.push_back(std::numeric_limits<std::size_t>::max());
        for (std::size_t k : bonds)
            key.insert(key.end(), {k, bonds_[k].bond.a, bonds_[k].bond.b});
        const auto it = caches.islands.find(members.front());
        if (it != caches.islands.end() && it->second->key == key)
            found[c] = std::move(it->second);
    }
    // An island whose nodes or bonds changed takes a factorisation left over (its workspace), analysed anew.
    std::vector<std::unique_ptr<DirectIsland>> spare;
    for (auto& [node, island] : caches.islands)
        if (island)
            spare.push_back(std::move(island));
    std::map<std::uint32_t, std::unique_ptr<DirectIsland>> kept;
    for (std::size_t c = 0; c < islands.size(); ++c) {
        if (!found[c] && !spare.empty()) {
            found[c] = std::move(spare.back());
            spare.pop_back();
        } else if (!found[c]) {
            found[c] = std::make_unique<DirectIsland>();
        }
        for (std::uint32_t i : islands[c])
            if (i < caches.touched.size() && caches.touched[i])
                found[c]->factored = false;
        kept[islands[c].front()] = std::move(found[c]);
    }
    caches.islands = std::move(kept);
    caches.touched.clear();
    DirectIsland* cache = nullptr;
    std::vector<std::uint32_t> order;
    std::vector<std::size_t> pattern, held, key;
    // A node's Jacobian for a weld: relative (linear, angular) acceleration from the node's (v, w).
    auto weldJ = [](const Vec3& r, double sign) {
        Mat6 j = Mat6::Identity();
        j.topRightCorner<3, 3>() = -skew(r);
        return Mat6(j * sign);
    };
    auto vec6 = [](const Vec3& a, const Vec3& b) {
        return (Vec6() << a.x, a.y, a.z, b.x, b.y, b.z).finished();
    };
    const Vec3 none;
    auto accel = [&](const Eigen::VectorXd& x, std::uint32_t n, Vec3& v, Vec3& w) {
        if (index[n] < 0) {
            v = w = none;
            return;
        }
        const Eigen::Index o = 6 * index[n];
        v = {x[o], x[o + 1], x[o + 2]};
        w = {x[o + 3], x[o + 4], x[o + 5]};
    };
    // A bond's 12 x 12 block of J^T E^-1 J (its held constraints), made again only when it changed.
    std::vector<char> signature;
    auto blockOf = [&](std::size_t k) -> const Eigen::Matrix<double, 12, 12>& {
        const BondState& b = bonds_[k];
        signature.clear();
        for (const BearingCorner& c : b.corners)
            signature.push_back(static_cast<char>(c.active + 2 * c.slip));
        if (k >= caches.blocks.size())
            caches.blocks.resize(bonds_.size());
        BondBlock& cached = caches.blocks[k];
        if (cached.compliance == delta && cached.broken == b.broken && cached.flags == signature)
            return cached.block;
        cached.compliance = delta;
        cached.broken = b.broken;
        cached.flags = signature;
        ++blocksMade_;
        Eigen::Matrix<double, 12, 12>& block = cached.block;
        block.setZero();
        if (!b.broken && b.corners.empty()) {
            Eigen::Matrix<double, 6, 12> j;
            j.leftCols<6>() = weldJ(b.ra, 1);
            j.rightCols<6>() = weldJ(b.rb, -1);
            const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> kinv(b.kinv);
            block = j.transpose() * kinv * j / delta;
        } else if (!b.broken) {
            const BondInterface& x = b.bond.section;
            const Vec3 dir[3] = {x.normal, x.u, x.v};
            for (const BearingCorner& c : b.corners) {
                if (!c.active)
                    continue;
                const double kk[3] = {c.kn, c.ku, c.kv};
                for (int d = 0; d < (c.slip ? 1 : 3); ++d) {
                    Eigen::Matrix<double, 12, 1> row;
                    row << vec6(dir[d], c.ca[d]), -vec6(dir[d], c.cb[d]);
                    if (kk[d] > 0)
                        block += row * row.transpose() / (delta * kk[d]);
                }
            }
        }
        return block;
    };
    Eigen::Index n = 0;
    std::vector<std::vector<int>> near; // each island node's neighbours and itself (its column's row blocks)
    // The island's matrix by 6 x 6 blocks: its pattern made when its key changes, masses then bonds added.
    auto assemble = [&]() -> const Sparse& {
        Sparse& a = cache->assembled;
        if (cache->assembledKey != key) {
            near.assign(order.size(), {});
            for (std::size_t j = 0; j < order.size(); ++j)
                near[j].push_back(static_cast<int>(j));
            for (std::size_t k : pattern) {
                const int e = index[bonds_[k].bond.a], f = index[bonds_[k].bond.b];
                if (e >= 0 && f >= 0) {
                    near[e].push_back(f);
                    near[f].push_back(e);
                }
            }
            Eigen::Index nonZeros = 0;
            for (std::vector<int>& rows : near) {
                std::sort(rows.begin(), rows.end());
                rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
                nonZeros += 36 * static_cast<Eigen::Index>(rows.size());
            }
            a = Sparse(n, n);
            a.resizeNonZeros(nonZeros);
            int* outer = a.outerIndexPtr();
            int* inner = a.innerIndexPtr();
            outer[0] = 0;
            for (std::size_t j = 0; j < order.size(); ++j)
                for (int q = 0; q < 6; ++q) {
                    int* at = inner + outer[6 * j + q];
                    for (int r : near[j])
                        for (int p = 0; p < 6; ++p)
                            *at++ = 6 * r + p;
                    outer[6 * j + q + 1] = static_cast<int>(at - inner);
                }
            // Each bond's block (e, f): its offset in the runs of f's six columns (-1: an end is held).
            cache->places.resize(pattern.size());
            for (std::size_t p = 0; p < pattern.size(); ++p) {
                const int ends[2] = {index[bonds_[pattern[p]].bond.a], index[bonds_[pattern[p]].bond.b]};
                for (int e = 0; e < 2; ++e)
                    for (int f = 0; f < 2; ++f)
                        cache->places[p][2 * e + f] =
                            ends[e] < 0 || ends[f] < 0
                                ? -1
                                : 6 * static_cast<int>(std::lower_bound(near[ends[f]].begin(),
                                                                        near[ends[f]].end(), ends[e]) -
                                                       near[ends[f]].begin());
            }
            cache->assembledKey = key;
        }
        const int* outer = a.outerIndexPtr();
        const int* inner = a.innerIndexPtr();
        double* values = a.valuePtr();
        std::fill(values, values + a.nonZeros(), 0.0);
        auto at = [&](int row, int col) -> double& { // row within the column's run, found by search
            return values[std::lower_bound(inner + outer[col], inner + outer[col + 1], row) - inner];
        };
        for (std::uint32_t i : order) {
            const NodeState& s = nodes_[i];
            const int o = 6 * index[i];
            for (int r = 0; r < 3; ++r) {
                at(o + r, o + r) += s.node.mass;
                for (int c = 0; c < 3; ++c)
                    at(o + 3 + r, o + 3 + c) += s.node.inertia.m[r][c];
            }
        }
        for (std::size_t p = 0; p < pattern.size(); ++p) {
            const BondState& b = bonds_[pattern[p]];
            const Eigen::Matrix<double, 12, 12>& block = blockOf(pattern[p]);
            const int ends[2] = {index[b.bond.a], index[b.bond.b]};
            for (int e = 0; e < 2; ++e)
                for (int f = 0; f < 2; ++f) {
                    const int place = cache->places[p][2 * e + f];
                    if (place < 0)
                        continue;
                    for (int c = 0; c < 6; ++c) {
                        double* column = values + outer[6 * ends[f] + c] + place;
                        for (int r = 0; r < 6; ++r)
                            column[r] += block(6 * e + r, 6 * f + c);
                    }
                }
        }
        return a;
    };
    // The corners whose held rows differ between the factorisation's flags and `flags`: each added row (over
    // sqrt(e)) is a column of the update C+, each removed one of the downdate C-; the factorisation becomes
    // that of A + C+ C+' - C- C-' and the assembled matrix is patched to match. False (nothing changed) when
    // more than kAmendRows rows change or it cannot (a large island, no CHOLMOD): then it is refactorised.
    std::vector<Eigen::Triplet<double>> ups, downs;
    auto amend = [&](const std::vector<char>& flags) {
        if (!cache->factored || !cache->numeric || cache->drift || cache->key != key ||
            cache->assembledKey != key || cache->compliance != delta || n >= kUpdateUnknowns ||
            flags.size() != cache->flags.size())
            return false;
        ups.clear();
        downs.clear();
        int columns[2] = {0, 0};
        auto rows = [](char flag) { return (flag & 1) ? ((flag & 2) ? 1 : 3) : 0; }; // its rows 0 .. rows - 1
        std::size_t f = 0;
        for (std::size_t k : pattern) {
            const BondState& b = bonds_[k];
            const BondInterface& x = b.bond.section;
            const Vec3 dir[3] = {x.normal, x.u, x.v};
            const int ends[2] = {index[b.bond.a], index[b.bond.b]};
            for (const BearingCorner& c : b.corners) {
                const int was = rows(cache->flags[f]), now = rows(flags[f]);
                ++f;
                if (b.broken || was == now)
                    continue;
                const double kk[3] = {c.kn, c.ku, c.kv};
                const bool up = now > was;
                for (int d = std::min(was, now); d < std::max(was, now); ++d) {
                    if (kk[d] <= 0)
                        continue;
                    Eigen::Matrix<double, 12, 1> row;
                    row << vec6(dir[d], c.ca[d]), -vec6(dir[d], c.cb[d]);
                    row /= std::sqrt(delta * kk[d]);
                    for (int e = 0; e < 2; ++e) {
                        if (ends[e] < 0)
                            continue;
                        for (int r = 0; r < 6; ++r)
                            (up ? ups : downs).emplace_back(6 * ends[e] + r, columns[up], row[6 * e + r]);
                    }
                    ++columns[up];
                }
            }
        }
        if (columns[0] + columns[1] > kAmendRows)
            return false;
        Sparse change[2];
        for (int up = 0; up < 2; ++up) {
            change[up].resize(n, columns[up]);
            change[up].setFromTriplets(up ? ups.begin() : downs.begin(), up ? ups.end() : downs.end());
        }
        // The update first: the matrix stays positive definite throughout.
        if (!cache->ldlt.updown(true, change[1]) || !cache->ldlt.updown(false, change[0])) {
            cache->numeric = cache->factored = false;
            return false;
        }
        Sparse& a = cache->assembled;
        const int* outer = a.outerIndexPtr();
        const int* inner = a.innerIndexPtr();
        double* values = a.valuePtr();
        for (int up = 0; up < 2; ++up)
            for (Eigen::Index j = 0; j < change[up].outerSize(); ++j)
                for (Sparse::InnerIterator q(change[up], j); q; ++q)
                    for (Sparse::InnerIterator r(change[up], j); r; ++r) {
                        const int col = static_cast<int>(q.row()), row = static_cast<int>(r.row());
                        const int* at = std::lower_bound(inner + outer[col], inner + outer[col + 1], row);
                        values[at - inner] += (up ? 1.0 : -1.0) * q.value() * r.value();
                    }
        cache->amended = true;
        return true;
    };
    auto factorize = [&] {
        std::vector<char> flags;
        for (std::size_t k : pattern)
            for (const BearingCorner& c : bonds_[k].corners)
                flags.push_back(static_cast<char>(c.active + 2 * c.slip));
        if (cache->factored && cache->key == key && cache->flags == flags && cache->compliance == delta)
            return true; // the structure and the active set are the last factorisation's
        if (amend(flags)) {
            cache->flags = std::move(flags);
            return true;
        }
        const Sparse& m = assemble();
        cache->flags = std::move(flags);
        if (cache->numeric && cache->key == key && cache->compliance == delta && n >= kUpdateUnknowns) {
            cache->matrix = m; // solved against, with the factorisation as preconditioner
            cache->drift = cache->factored = true;
            return true;
        }
        cache->factored = cache->numeric = cache->drift = cache->amended = false;
        cache->matrix = Sparse();
        if (!cache->analysed || cache->key != key) {
            cache->ldlt.small(n < kUpdateUnknowns);
            cache->ldlt.analyzePattern(m);
            cache->key = key;
            cache->analysed = true;
            ++analyses_;
        }
        cache->ldlt.factorize(m);
        ++factorizations_;
        cache->compliance = delta;
        cache->factored = cache->numeric = cache->ldlt.info() == Eigen::Success;
        return cache->factored;
    };
    // Conjugate gradient on `matrix`, preconditioned by the factorisation of the numbers before its bonds
    // broke or corners changed: a change of low rank takes a few iterations; after up/down-dates, on the
    // assembled matrix (a refinement: none when the factor is exact). False when it does not converge.
    Eigen::VectorXd rhs, x, res, pre, way, aWay;
    auto update = [&] {
        const Sparse& a = cache->drift ? cache->matrix : cache->assembled;
        x = cache->ldlt.solve(rhs);
        res = rhs - a * x;
        const double goal = 1e-10 * rhs.norm();
        if (res.norm() <= goal)
            return true;
        pre = cache->ldlt.solve(res);
        way = pre;
        double rz = res.dot(pre);
        for (int it = 0; it < kUpdateIterations && res.norm() > goal; ++it) {
            aWay = a * way;
            const double pq = way.dot(aWay);
            if (!(pq > 0))
                return false;
            const double alpha = rz / pq;
            x += alpha * way;
            res -= alpha * aWay;
            pre = cache->ldlt.solve(res);
            const double next = res.dot(pre);
            way = pre + (next / rz) * way;
            rz = next;
        }
        return res.norm() <= goal;
    };
    auto worst = [&] {
        double m = 0;
        for (std::uint32_t i : order)
            m = std::max(m, nodeResidual(nodes_[i]));
        return m;
    };
    // One augmented-Lagrangian step: solve for a', move every held constraint's force by -E^-1 J a'.
    auto step = [&] {
        for (std::uint32_t i : order) {
            const NodeState& s = nodes_[i];
            const Vec3 lw = s.node.inertia * s.w;
            rhs.segment<6>(6 * index[i]) = vec6(s.v * s.node.mass, lw);
        }
        const bool refine = cache->drift || cache->amended, solved = refine && update();
        if (refine && !solved) { // too far from the factorisation: a fresh one
            cache->ldlt.factorize(cache->drift ? cache->matrix : cache->assembled);
            ++factorizations_;
            cache->matrix = Sparse();
            cache->drift = cache->amended = false;
            cache->factored = cache->numeric = cache->ldlt.info() == Eigen::Success;
        }
        if (!solved)
            x = cache->numeric ? Eigen::VectorXd(cache->ldlt.solve(rhs)) : Eigen::VectorXd::Zero(n);
        for (std::size_t k : held) {
            BondState& b = bonds_[k];
            Vec3 va, wa, vb, wb;
            accel(x, b.bond.a, va, wa);
            accel(x, b.bond.b, vb, wb);
            if (b.corners.empty()) {
                const Vec3 lin = (va + cross(wa, b.ra)) - (vb + cross(wb, b.rb)), ang = wa - wb;
                const Vec6 rel = vec6(lin, ang);
                const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> kinv(b.kinv);
                const Vec6 d = -(kinv * rel) / delta;
                const Vec3 df{d[0], d[1], d[2]}, dm{d[3], d[4], d[5]};
                b.force += df;
                b.moment += dm;
                apply(b, df, dm);
                continue;
            }
            const BondInterface& sec = b.bond.section;
            const Vec3 dir[3] = {sec.normal, sec.u, sec.v};
            NodeState& na = nodes_[b.bond.a];
            NodeState& nb = nodes_[b.bond.b];
            for (BearingCorner& c : b.corners) {
                if (!c.active)
                    continue;
                const double kk[3] = {c.kn, c.ku, c.kv};
                for (int d = 0; d < (c.slip ? 1 : 3); ++d) {
                    if (kk[d] <= 0)
                        continue;
                    const double rel = dot(va - vb, dir[d]) + dot(wa, c.ca[d]) - dot(wb, c.cb[d]);
                    const double l = -rel / (delta * kk[d]); // along dir[d] on a, its opposite on b
                    na.v += dir[d] * (l * na.invMass);
                    na.w += c.ia[d] * l;
                    nb.v -= dir[d] * (l * nb.invMass);
                    nb.w -= c.ib[d] * l;
                    (d == 0 ? c.press : d == 1 ? c.gu : c.gv) += d == 0 ? -l : l;
                }
            }
        }
        ++sweeps_;
        traceSweep();
    };
    // Sets a corner's forces (press, friction along u and v), applying the change to its nodes.
    auto set = [&](BondState& b, BearingCorner& c, double press, double gu, double gv) {
        NodeState& na = nodes_[b.bond.a];
        NodeState& nb = nodes_[b.bond.b];
        const BondInterface& sec = b.bond.section;
        const Vec3 dir[3] = {sec.normal, sec.u, sec.v};
        const double l[3] = {c.press - press, gu - c.gu, gv - c.gv};
        for (int d = 0; d < 3; ++d) {
            na.v += dir[d] * (l[d] * na.invMass);
            na.w += c.ia[d] * l[d];
            nb.v -= dir[d] * (l[d] * nb.invMass);
            nb.w -= c.ib[d] * l[d];
        }
        c.press = press;
        c.gu = gu;
        c.gv = gv;
    };
    // A corner leaves the set: its forces go.
    auto release = [&](BondState& b, BearingCorner& c) {
        set(b, c, 0, 0, 0);
        c.active = false;
    };
    // Friction within its limit; returns true when it had to be cut (the corner then slips).
    auto limit = [&](BondState& b, BearingCorner& c) {
        const double grip = b.limits.friction * std::max(c.press, 0.0), g = std::hypot(c.gu, c.gv);
        if (g <= grip * (1 + 1e-9))
            return false;
        const double f = g > 0 ? grip / g : 0.0;
        set(b, c, c.press, c.gu * f, c.gv * f);
        return true;
    };
    const double target2 = tolerance * tolerance / 4;
    sweeps_ = 0;
    for (std::size_t island = 0; island < islands.size(); ++island) {
        order = islands[island];
        if (worst() <= tolerance * tolerance)
            continue; // at rest: its factorisation waits
        cache = caches.islands[order.front()].get();
        key = keys[island];
        pattern = patterns[island];
        held.clear();
        for (std::size_t k : pattern)
            if (!bonds_[k].broken)
                held.push_back(k);
        n = static_cast<Eigen::Index>(6 * order.size());
        rhs.resize(n);
        for (int round = 0; round < 3 && factorize(); ++round) {
            double last = worst();
            for (int i = 0; i < 12 && last > target2; ++i) {
                step();
                const double now = worst();
                if (now > 0.9 * last && i >= 2)
                    break;
                last = now;
            }
            const bool settled = last <= target2; // then only corners that pull or slip change the set
            bool changed = false;
            for (std::size_t p = 0; p < pattern.size(); ++p) {
                BondState& b = bonds_[pattern[p]];
                if (b.broken)
                    continue;
                double total = 0;
                for (const BearingCorner& c : b.corners)
                    total += std::abs(c.press);
                for (BearingCorner& c : b.corners) {
                    bool moved = false;
                    if (c.active && c.press < -1e-6 * total) {
                        release(b, c);
                        moved = true;
                    } else if (c.active) { // sticking past the friction limit: it slips (its friction a
                                           // force)
                        const bool cut = limit(b, c);
                        moved = cut && !c.slip;
                        c.slip = c.slip || cut;
                    } else if (!settled) {
                        const NodeState& na = nodes_[b.bond.a];
                        const NodeState& nb = nodes_[b.bond.b];
                        const double rel =
                            dot(na.v - nb.v, b.bond.section.normal) + dot(na.w, c.ca[0]) - dot(nb.w, c.cb[0]);
                        c.active = moved = rel > tolerance;
                    }
                    changed = changed || moved;
                }
            }
            if (!changed)
                break;
        }
        for (std::size_t k : held) // what still pulls lets go; Gauss-Seidel takes it from here
            for (BearingCorner& c : bonds_[k].corners) {
                if (c.press < 0)
                    release(bonds_[k], c);
                limit(bonds_[k], c);
            }
    }
    const int directSweeps = sweeps_;
    caches.polishing = true;
    solveGaussSeidel(tolerance);
    caches.polishing = false;
    sweeps_ += directSweeps;
}

// Bearings' resultants, the residual, and the count of solves each node has been left unbalanced.
void StressSolver::finishSolve(double scale) {
    for (BondState& b : bonds_)
        if (!b.broken && b.solvable && !b.corners.empty())
            gatherBearing(b);
    double max2 = 0;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i) {
        NodeState& n = nodes_[i];
        if (movable(i) || n.stalled) // what the solve left out still counts: it is not in equilibrium
            max2 = std::max(max2, nodeResidual(n));
        const bool moving = length(n.v) > settings_.unbalanced || length(n.w) > settings_.unbalanced;
        n.unbalanced = n.bearings > 0 && n.invMass > 0 && !n.detached && moving ? n.unbalanced + 1 : 0;
        n.stalled = false;
    }
    residual_ = scale > 0 ? std::sqrt(max2) / scale : 0.0;
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
        const double hit = amount * (1 - d / radius);
        if (b.health - hit <= 0)
            breaks_.push_back({i, b.force, b.moment, utilisation(i), true});
        b.health -= hit;
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
        if (const double u = utilisation(i); u > 1) {
            out.push_back(i);
            breaks_.push_back({i, bonds_[i].force, bonds_[i].moment, u, false});
        }
    }
    for (std::size_t i : out)
        breakBond(i);
    return out;
}

std::vector<BondBreak> StressSolver::takeBreaks() {
    std::vector<BondBreak> out;
    out.swap(breaks_);
    return out;
}

void StressSolver::setHealth(std::size_t i, double health) {
    bonds_[i].health = std::clamp(health, 0.0, 1.0);
    if (bonds_[i].health <= 0)
        breakBond(i);
}

void StressSolver::breakBond(std::size_t i) {
    if (direct_) {
        direct_->touch(bonds_[i].bond.a);
        direct_->touch(bonds_[i].bond.b);
    }
    if (!bonds_[i].broken) {
        markDirty(bonds_[i].bond.a);
        markDirty(bonds_[i].bond.b);
        reachValid_ = false;
        reachLost_.push_back(bonds_[i].bond.a);
        reachLost_.push_back(bonds_[i].bond.b);
    }
    bonds_[i].broken = true;
    bonds_[i].force = bonds_[i].moment = Vec3{};
}

void StressSolver::detach(std::uint32_t node) {
    nodes_[node].detached = true;
    markDirty(node);
    reachValid_ = false;
    reachFull_ = true;
    for (std::size_t i : nodes_[node].bonds)
        breakBond(i);
}

std::vector<std::uint32_t> StressSolver::unsupported() const {
    const std::vector<char> fresh = reachValid_ ? std::vector<char>{} : reachable();
    const std::vector<char>& r = reachValid_ ? reached_ : fresh;
    std::vector<std::uint32_t> out;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
        if ((!r[i] || nodes_[i].unbalanced >= settings_.unbalancedSolves) && !nodes_[i].detached)
            out.push_back(i);
    return out;
}

} // namespace rubble
