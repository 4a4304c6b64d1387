#pragma once
/// \file Journal.hpp
/// The destruction journal: every impact a DestructionWorld accepted and every object removed, in order,
/// as compact events. Replayed on a fresh world built from the same scene, it rebuilds the same geometry
/// (docs/journal.md).

#include <array>
#include <cstdint>

#include "rubble/core/Export.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble {

/// What a journal event records.
enum class JournalEventKind : std::uint8_t {
    Impact = 1, ///< an accepted impact
    Remove = 2, ///< an object removed by the game (retired debris, a removed body)
};

/// One journal event. Coordinates are in the object's local frame, in single precision: the world rounds
/// every accepted impact to these values before it fractures with it, so a replay runs the same numbers.
struct RUBBLE_API JournalEvent {
    JournalEventKind kind = JournalEventKind::Impact; ///< impact or removal
    std::uint32_t object = 0;                         ///< the object (ObjectId)
    std::uint32_t tick = 0;                           ///< DestructionWorld::frame() when it happened
    std::array<float, 3> point{};                     ///< impact point (object coordinates)
    std::array<float, 3> normal{};                    ///< impact normal (object coordinates)
    float impulse = 0;                                ///< impulse (N·s)
    std::uint8_t pattern = 0;                         ///< the object's patternByte() (checked on replay)
    std::uint16_t cells = 0;                          ///< the object's shatter cell count (checked on replay)
    std::uint64_t seed = 0; ///< the seed of the object's next fracture job (checked on replay)

    /// The impact in double precision (exactly the values the world fractured with).
    Impact impact() const {
        return Impact{{point[0], point[1], point[2]}, {normal[0], normal[1], normal[2]}, impulse};
    }
    /// Same fields.
    bool operator==(const JournalEvent&) const = default;
};

/// A fracture's pattern as one byte: the CellPattern in the low four bits, the ShatterLayout above them.
inline std::uint8_t patternByte(const FractureParams& f) {
    return static_cast<std::uint8_t>(static_cast<unsigned>(f.pattern) | static_cast<unsigned>(f.layout) << 4);
}

/// Whether a pattern byte names a known CellPattern and ShatterLayout.
inline bool validPatternByte(std::uint8_t b) {
    return (b & 15u) <= static_cast<unsigned>(CellPattern::Adaptive) &&
           (b >> 4) <= static_cast<unsigned>(ShatterLayout::Uniform);
}

/// An impact rounded to the journal's precision (what DestructionWorld::submitImpact fractures with).
inline Impact journalPrecision(const Impact& i) {
    auto f = [](double x) { return static_cast<double>(static_cast<float>(x)); };
    return Impact{{f(i.point.x), f(i.point.y), f(i.point.z)},
                  {f(i.normal.x), f(i.normal.y), f(i.normal.z)},
                  f(i.impulse)};
}

} // namespace rubble
