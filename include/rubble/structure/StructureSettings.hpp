#pragma once
/// \file StructureSettings.hpp
/// Settings of a structure: how bonds are found (BondGraph) and how the stress solver iterates
/// (StressSolver), without the solver itself.

#include "rubble/core/Export.hpp"
#include "rubble/core/Vec3.hpp"

namespace rubble {

/// How touching is decided.
struct RUBBLE_API BondSettings {
    double gap = 1e-3;         ///< faces at most this far apart (m) count as touching
    double angleTolerance = 1; ///< faces within this angle (degrees) of anti-parallel count as coplanar
    double minArea = 1e-6;     ///< patches below this area (m^2) make no bond
};

/// How StressSolver::solve() iterates (docs/structure.md, "Convergence").
enum class StressMethod {
    SweepBudget, ///< Gauss-Seidel over every bond, at most `iterations` sweeps (StressSettings' default)
    GaussSeidel, ///< Gauss-Seidel over the bonds of the nodes not at rest, until `residual` is met
    ConjugateGradient, ///< block-Jacobi preconditioned conjugate gradient on the welds, until `residual`
    Direct ///< sparse Cholesky of the regularised bond system with an active set for bearings, then
           ///< Gauss-Seidel until `residual` (friction limits, what bearings cannot hold)
    ,
    Auto ///< Direct while the structure has bearings, else GaussSeidel (the runtime's default)
};

/// Settings of the stress solver.
struct RUBBLE_API StressSettings {
    StressSettings() = default;
    /// The defaults, iterating by `how`.
    explicit StressSettings(StressMethod how) : method(how) {}
    int iterations = 25;       ///< Gauss-Seidel sweeps over all bonds per solve(), at most
    double tolerance = 0.01;   ///< m/s^2 (and rad/s^2), SweepBudget: fewer sweeps once every bonded node's
                               ///< acceleration is below it; 0: always `iterations`
    Vec3 gravity{0, -9.81, 0}; ///< m/s^2
    double unbalanced = 0.5;   ///< m/s^2 (and rad/s^2): a node left accelerating this much is not held
    int unbalancedSolves = 30; ///< ... after this many solves in a row (the warm-started solve converges)
    StressMethod method = StressMethod::SweepBudget; ///< how solve() iterates (docs/structure.md)
    double residual = 1e-3; ///< GaussSeidel, ConjugateGradient, Direct: the relative residual solve() reaches
    int maxSweeps = 5000;   ///< ... sweeps at most (what bearings cannot hold never converges)
    bool deadLoadGuess = false; ///< GaussSeidel, ConjugateGradient: a structure whose bonds carry nothing yet
                                ///< starts from its dead load passed down (off: it biases which equilibrium
                                ///< indeterminate contacts reach; docs/structure.md)
    bool trace = false;         ///< record the relative residual after every sweep (history())
    bool routeLoads = true;     ///< GaussSeidel, ConjugateGradient: a change of a node's load since the last
                            ///< solve is first passed down the welds beneath it to the ground (a warm start)
    double compliance = 1e-6; ///< Direct: each constraint's regularisation, relative to its effective mass
    int stallSweeps = 64;     ///< GaussSeidel (Direct: every quarter of it): after this many sweeps, nodes on
                          ///< bearings the last solve left unbalanced and still accelerating by `unbalanced`
                          ///< are left out (forces kept); Direct also, every this many, those stuck; 0: never
};

} // namespace rubble
