#pragma once
/// \file StressSolver.hpp
/// Bond forces of a structure under gravity and contact loads (an iterative, warm-started solve of rigid
/// bond constraints, as in NVIDIA Blast's stress solver), the stresses they cause over each bond's section,
/// breaking and damage. Theory and validation in docs/structure.md.

#include <cstdint>
#include <memory>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Vec3.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/structure/BondGraph.hpp"
#include "rubble/structure/Material.hpp"
#include "rubble/structure/StructureSettings.hpp"

namespace rubble {

/// One rigid part of a structure.
struct RUBBLE_API StructureNode {
    double mass = 0;   ///< kg
    Vec3 centroid;     ///< centre of mass
    Mat3 inertia;      ///< inertia tensor about the centre of mass, kg m^2
    bool root = false; ///< held in place (ground, scenery)
};

/// The node of a solid of convex parts with the given density (kg/m^3).
RUBBLE_API StructureNode structureNode(const std::vector<ConvexPolytope>& parts, double density, bool root);

/// What a bond withstands, in Pa (0: unlimited).
struct RUBBLE_API StrengthLimits {
    double compressive = 0; ///< Pa
    double tensile = 0;     ///< Pa
    double shear = 0;       ///< Pa
    double friction = 0;    ///< > 0: a bearing (dry contact) with this friction coefficient, not a weld
};

/// The limits of a bond between two materials: the weaker of each.
RUBBLE_API StrengthLimits bondLimits(const Material& a, const Material& b);

/// The stresses over a bond's section (Pa), at the current health.
struct RUBBLE_API BondStress {
    double compression = 0; ///< largest compressive normal stress (axial plus bending)
    double tension = 0;     ///< largest tensile normal stress (axial plus bending)
    double shear = 0;       ///< mean transverse shear plus the largest torsional shear
};

/// A bond that broke in breakOverstressed() or damage(), with what it carried the moment it broke.
struct RUBBLE_API BondBreak {
    std::size_t bond = 0;   ///< its slot (its section stays readable until the slot is reused)
    Vec3 force;             ///< the force node b exerted on node a (N)
    Vec3 moment;            ///< the couple node b exerted on node a about the section centroid (N m)
    double utilisation = 0; ///< its largest stress over limit (> 1 when overstressed)
    bool damaged = false;   ///< broken by damage (health 0), not by stress
};

/// The stress solver over one structure (nodes joined by bonds).
class RUBBLE_API StressSolver {
public:
    /// An empty structure.
    explicit StressSolver(StressSettings settings = {}) : settings_(settings) {}

    /// Replaces the structure; limits[i] belongs to bonds[i]. Accumulated forces and health are reset.
    void reset(std::vector<StructureNode> nodes, std::vector<Bond> bonds, std::vector<StrengthLimits> limits);
    /// Adds a node (in a free slot when there is one); returns its index.
    std::uint32_t addNode(const StructureNode& node);
    /// Removes a node and its bonds; its index is free for a later addNode. Until the next solve, bonds added
    /// to its former neighbours across the same faces inherit the forces its bonds carried (by area): the
    /// pieces that replace a fractured body start from its load path.
    void removeNode(std::uint32_t node);
    /// Adds a bond between present nodes (in a free slot when there is one); returns its index. The other
    /// bonds keep their forces and health.
    std::size_t addBond(Bond bond, StrengthLimits limits);
    /// Makes a node a root (held) or not; its bonds' effective masses follow.
    void setRoot(std::uint32_t node, bool root);
    /// True when the node is present (added and not removed).
    bool present(std::uint32_t node) const { return node < nodes_.size() && !nodes_[node].removed; }
    /// True when the node is held (a root).
    bool root(std::uint32_t node) const { return nodes_[node].node.root; }
    /// The bonds of a node (broken ones included), ascending.
    const std::vector<std::size_t>& bondsOf(std::uint32_t node) const { return nodes_[node].bonds; }
    /// Settings (may change between solves).
    StressSettings& settings() { return settings_; }

    /// Adds a load on a node for the next solve (e.g. a contact force), applied at a point.
    void addLoad(std::uint32_t node, const Vec3& force, const Vec3& point);
    /// Runs the bounded iterations, starting from the previous solve's bond forces; consumes the loads.
    void solve();

    /// Sweeps (or conjugate-gradient iterations; Direct: solves with the factorisation plus Gauss-Seidel
    /// sweeps) the last solve() ran.
    int sweeps() const { return sweeps_; }
    /// Direct: numeric factorisations the last solve() ran (one per changed island and active set; 0 when
    /// the kept ones hold or, on a large island, a change is solved against them).
    int factorizations() const { return factorizations_; }
    /// Direct: symbolic analyses so far (a new one only when the nodes or the bonds present change).
    int analyses() const { return analyses_; }
    /// Direct: bonds whose 12 x 12 block the last solve() made anew (new, or their break or active set
    /// changed).
    int blocksMade() const { return blocksMade_; }
    /// The last solve()'s relative residual: the largest remaining acceleration of a supported node (its
    /// linear and angular parts in the mass metric, m/s^2) over the largest acceleration the loads alone
    /// give.
    double residual() const { return residual_; }
    /// With StressSettings::trace: the relative residual after each sweep of the last solve().
    const std::vector<double>& history() const { return history_; }
    /// Bond slots (removed bonds leave free slots, which count as broken).
    std::size_t bondCount() const { return bonds_.size(); }
    /// Node slots (removed nodes leave free slots, never unsupported).
    std::size_t nodeCount() const { return nodes_.size(); }
    /// The bond (its section and nodes).
    const Bond& bond(std::size_t i) const { return bonds_[i].bond; }
    /// The force that node b exerts on node a through the bond (N).
    Vec3 bondForce(std::size_t i) const { return bonds_[i].force; }
    /// The couple that node b exerts on node a through the bond, about the section centroid (N m).
    Vec3 bondMoment(std::size_t i) const { return bonds_[i].moment; }
    /// The stresses over the bond's section at its current health.
    BondStress stress(std::size_t i) const;
    /// The largest ratio of a stress to its limit (1 = breaking; 0 for a broken bond). A bearing carries
    /// compression only, its resultant inside the contact patch and its transverse force within friction: the
    /// solve keeps it there (a body it cannot hold is unbalanced, see unsupported()), and it breaks only by
    /// crushing.
    double utilisation(std::size_t i) const;
    /// The bond's remaining fraction of section, 1 when whole.
    double health(std::size_t i) const { return bonds_[i].health; }
    /// True when the bond has broken.
    bool broken(std::size_t i) const { return bonds_[i].broken; }

    /// Weakens bonds whose centroid lies within radius of point: health drops by amount * (1 - d / radius).
    /// Bonds reaching 0 break.
    void damage(const Vec3& point, double radius, double amount);
    /// Breaks every bond whose stress exceeds its limits; returns them, ascending.
    std::vector<std::size_t> breakOverstressed();
    /// Sets a bond's health (e.g. carried over from an earlier graph); 0 breaks it.
    void setHealth(std::size_t i, double health);
    /// Breaks one bond.
    void breakBond(std::size_t i);
    /// Takes a node out of the structure (it fell or was removed); its bonds break.
    void detach(std::uint32_t node);
    /// The bonds broken by breakOverstressed() and damage() since the last call, in the order they broke;
    /// clears the list.
    std::vector<BondBreak> takeBreaks();
    /// Nodes still in the structure that no chain of intact bonds links to a root, or that bearings have not
    /// held in equilibrium for `StressSettings::unbalancedSolves` solves in a row (tipping or sliding),
    /// ascending.
    std::vector<std::uint32_t> unsupported() const;

private:
    struct NodeState {
        StructureNode node;
        double invMass = 0;
        Mat3 invInertia;
        Vec3 v, w;          // velocity change this solve
        Vec3 force, torque; // loads this solve
        Vec3 fv, fw;        // the loads' (and gravity's) part of v and w
        bool dirty = false; // v and w to be recomputed from the bonds at the next solve
        bool detached = false;
        bool removed = false;           // a free slot
        bool stalled = false;           // GaussSeidel: left out of this solve (unbalanced on bearings)
        bool solved = false;            // loads recorded by a solve (fv, fw), so a change can be routed
        int unbalanced = 0;             // solves in a row that left it accelerating
        int bearings = 0;               // bearings it rests on (or carries)
        std::vector<std::size_t> bonds; // ascending
    };
    struct BearingCorner {
        Vec3 offset;                   // from the section centroid (world)
        Vec3 ra, rb;                   // from each node's centre of mass
        double kn = 0, ku = 0, kv = 0; // inverse effective masses along the normal and the in-plane axes
        double press = 0;              // accumulated normal force (>= 0: compression)
        double gu = 0, gv = 0;         // accumulated friction along u and v (|g| <= friction * press)
        Vec3 ca[3], cb[3];             // ra x d and rb x d for d = normal, u, v
        Vec3 ia[3], ib[3];             // the inverse inertias times those: the spin an impulse along d gives
        bool active = true;            // Direct: in the active set (held as an equality)
        bool slip = false;             // Direct: friction at its limit (a force, not held)
    };
    struct BondState {
        Bond bond;
        StrengthLimits limits;
        Vec3 ra, rb;       // section centroid relative to each node's centre of mass
        double kinv[36]{}; // inverse of the 6x6 effective mass
        bool solvable = false;
        Vec3 force, moment; // accumulated (warm start)
        double health = 1;
        bool broken = false;
        bool removed = false;               // a free slot
        std::vector<BearingCorner> corners; // bearing: contact points at the patch's hull corners
        /// A weld (no bearing corners) that holds and can be solved.
        bool intactWeld() const { return !broken && solvable && corners.empty(); }
    };
    void prepare(BondState& b);
    void removeBond(std::size_t i);
    void apply(BondState& b, const Vec3& force, const Vec3& moment);
    double bearingUtilisation(const BondState& b) const;
    void solveBearing(BondState& b);
    void gatherBearing(BondState& b);
    void solveWeld(BondState& b);
    void markDirty(std::uint32_t node);
    double startSolve();
    void reach();
    bool reachAgain();
    void spread(std::vector<char>& reached, std::vector<std::uint32_t>& open) const;
    std::vector<char> reachable() const;
    double nodeResidual(const NodeState& n) const;
    bool movable(std::uint32_t i) const;
    void solveSweepBudget();
    void solveGaussSeidel(double tolerance);
    void solveConjugateGradient(double tolerance);
    void solveDirect(double tolerance);
    void finishSolve(double scale);
    void traceSweep();

    StressSettings settings_;
    std::vector<NodeState> nodes_;
    std::vector<BondState> bonds_;
    std::vector<std::uint32_t> freeNodes_; // descending pops give the lowest slot first
    std::vector<std::uint32_t> checked_;   // solve(): the nodes whose rest ends the sweeps
    int sweeps_ = 0;
    int factorizations_ = 0;
    int analyses_ = 0;
    int blocksMade_ = 0;
    struct DirectCache;                   // Direct: the symbolic factorisation and its pattern
    std::shared_ptr<DirectCache> direct_; // (a copy shares it until its next solve)
    double residual_ = 0;
    double scale_ = 0; // the last solve's residual scale (m/s^2)
    std::vector<double> history_;
    std::vector<std::size_t> freeBonds_;
    std::vector<std::uint32_t> dirty_;                // nodes whose v and w the next solve recomputes
    bool allDirty_ = true;                            // every node's (gravity changed, or never solved)
    Vec3 gravity_;                                    // the gravity v and w hold
    std::vector<char> reached_;                       // a chain of intact bonds links the node to a root
    bool reachValid_ = false;                         // reached_ matches the bonds
    bool reachFull_ = true;                           // reached_ must be found again from every root
    std::size_t bearingBonds_ = 0;                    // bonds with friction (bearings)
    StressMethod method_ = StressMethod::SweepBudget; // the method of the solve in progress (Auto resolved)
    std::vector<std::uint32_t> reachLost_;            // ends of bonds gone since: may have lost their chain
    std::vector<std::uint32_t> reachGained_;          // ends of bonds added since: may have gained one
    struct Orphan {                                   // the load a removed node's bond put on a neighbour
        std::uint32_t node;                           // the neighbour
        Vec3 force, moment;                           // on it, the moment about the section centroid
        Vec3 centroid, normal;                        // the section's
    };
    void inherit();
    void coldStart();
    struct Route { // a load change on a node to pass down: force, and torque about its centroid
        std::uint32_t node;
        Vec3 force, torque;
    };
    void route(std::vector<Route>& changes);
    void settleAmong(const std::vector<std::uint32_t>& group, double tolerance);
    std::vector<std::size_t> balanceDown(const std::vector<std::uint32_t>& group);
    void routeUnbalanced(double tolerance);
    bool weldBeneath(std::size_t k, std::uint32_t n, const Vec3& down, bool steep) const;
    Route unbalance(std::uint32_t n) const;
    bool balanceAmong(const std::vector<std::uint32_t>& group, const std::vector<std::size_t>& welds);
    std::vector<Route> routes_;            // startSolve(): this solve's load changes
    std::vector<BondBreak> breaks_;        // since takeBreaks()
    std::vector<Orphan> orphans_;          // since the last solve
    std::vector<std::size_t> fresh_;       // bonds added since the last solve
    std::vector<std::uint32_t> bondStamp_; // GaussSeidel: the sweep that listed the bond
    std::vector<std::uint32_t> nodeStamp_; // ... that moved the node
    std::uint32_t stampNow_ = 0;
};

} // namespace rubble
