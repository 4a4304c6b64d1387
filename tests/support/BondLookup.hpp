#pragma once
// The stress-solver tests' lookup of a bond by the nodes it joins.

#include <gtest/gtest.h>

#include <algorithm>

#include "rubble/structure/StressSolver.hpp"

namespace rubble::test {

/// The index of the bond between nodes a and b (a failure when there is none).
inline std::size_t bondBetween(const StressSolver& s, std::uint32_t a, std::uint32_t b) {
    for (std::size_t i = 0; i < s.bondCount(); ++i)
        if (s.bond(i).a == std::min(a, b) && s.bond(i).b == std::max(a, b))
            return i;
    ADD_FAILURE() << "no bond " << a << "-" << b;
    return 0;
}

} // namespace rubble::test
