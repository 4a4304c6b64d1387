#pragma once
// Orders and keys of points by their coordinates' bits: lexicographic order, and the bits as a sortable key.

#include <array>
#include <bit>
#include <cstdint>
#include <tuple>

#include "rubble/core/Vec3.hpp"

namespace rubble::detail {

/// True when a comes before b by x, then y, then z.
inline bool lexLess(const Vec3& a, const Vec3& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
}

/// The coordinates' bits: equal exactly for bit-equal points.
inline std::array<std::uint64_t, 3> pointBits(const Vec3& p) {
    return {std::bit_cast<std::uint64_t>(p.x), std::bit_cast<std::uint64_t>(p.y),
            std::bit_cast<std::uint64_t>(p.z)};
}

} // namespace rubble::detail
