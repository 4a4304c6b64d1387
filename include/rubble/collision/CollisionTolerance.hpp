#pragma once
/// \file CollisionTolerance.hpp
/// The tolerances that collision parts keep, shared by the decomposition, the writers, the runtime and
/// `rubble check` (docs/collision.md).

#include <cstddef>

namespace rubble {

/// Collision parts reach at most this fraction of their piece's bounding-box diagonal outside the piece's
/// convex hull.
inline constexpr double kPartHullTolerance = 0.01;

/// The parts of a piece overlap another piece of the same fracture by at most this fraction of the smaller
/// piece's volume, while the part budget allows.
inline constexpr double kPartOverlapTolerance = 0.01;

/// A remainder keeps up to this many times DecompositionParams::maxParts parts rather than merge two of them
/// into a hull that covers a crater.
inline constexpr std::size_t kCraterBudgetFactor = 2;

/// How far collision parts may reach outside the convex hull of an object of the given bounding-box diagonal.
inline double partHullTolerance(double diagonal) {
    return kPartHullTolerance * diagonal;
}

} // namespace rubble
