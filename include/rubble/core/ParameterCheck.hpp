#pragma once
/// \file ParameterCheck.hpp
/// The accepted values of the parameters every API takes (C++, C, Python, the CLI) and the one check that
/// refuses a value outside them, with one message naming the parameter and its range (docs/robustness.md).

#include <cstdint>
#include <string>
#include <string_view>

#include "rubble/core/Export.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/core/Vec3.hpp"

namespace rubble {

/// What kind of value a parameter takes.
enum class ParamKind : std::uint8_t {
    Real,      ///< a finite number in [lo, hi] ((lo, hi] when loOpen)
    Integer,   ///< a whole number in [lo, hi]
    Point,     ///< three finite numbers
    Direction, ///< three finite numbers, not all zero
};

/// The accepted values of one parameter.
struct RUBBLE_API ParamRange {
    std::string_view name; ///< as every API spells it (C++ member, C field, Python keyword, --name)
    ParamKind kind = ParamKind::Real; ///< what it takes
    long double lo = 0;               ///< lowest accepted value (Real, Integer)
    long double hi = 0;               ///< highest accepted value (Real, Integer)
    bool loOpen = false;              ///< lo itself is refused
};

/// The most cells a Shatter pattern has (fracture refuses more).
inline constexpr int kMaxShatterCells = 1000;
/// The most octaves a Roughness may have.
inline constexpr int kMaxRoughOctaves = 10;
/// Largest DecompositionParams::maxParts: every part costs a search over candidate planes.
inline constexpr int kMaxConvexParts = 1024;
/// The most levels of a pre-fracture (`rubble fracture --depth`).
inline constexpr int kMaxFractureDepth = 4;
/// The most pieces a pre-fracture may make (piecesBound of its cells and depth).
inline constexpr long double kMaxTotalPieces = 10000;
/// The largest impulse (N s).
inline constexpr long double kMaxImpulse = 1e12L;
/// The largest density.
inline constexpr long double kMaxDensity = 1e9L;

/// Every checked parameter; a new one joins with one line.
inline constexpr ParamRange kParamRanges[] = {
    {"impulse", ParamKind::Real, 0, kMaxImpulse},
    {"normal", ParamKind::Direction},
    {"point", ParamKind::Point},
    {"cells", ParamKind::Integer, 1, kMaxShatterCells},
    {"depth", ParamKind::Integer, 1, kMaxFractureDepth},
    {"seed", ParamKind::Integer, 0, 18446744073709551615.0L},
    {"density", ParamKind::Real, 0, kMaxDensity, true},
    {"max_parts", ParamKind::Integer, 1, kMaxConvexParts}, // DecompositionParams::maxParts
    {"roughness", ParamKind::Real, 0, 1},                  // Roughness::amplitude, relative to the cell size
    {"feature_size", ParamKind::Real, 0, 4}, // Roughness::featureSize, relative to the cell size
    {"hurst", ParamKind::Real, 0, 1, true},
    {"octaves", ParamKind::Integer, 1, kMaxRoughOctaves},
    {"grain_stretch", ParamKind::Real, 1, 100},
    {"grain", ParamKind::Point},
    {"force", ParamKind::Point}, // a load on a structure's body (N)
    {"max_triangles_per_piece", ParamKind::Integer, 64, 10'000'000},
};

/// The range of an absolute Roughness::amplitude or featureSize (the table's are relative).
inline constexpr ParamRange kAbsoluteRoughness{"roughness", ParamKind::Real, 0, 1e6};
/// The range of an absolute Roughness::featureSize.
inline constexpr ParamRange kAbsoluteFeatureSize{"feature_size", ParamKind::Real, 0, 1e6};

/// The range of the parameter called name, or null.
RUBBLE_API const ParamRange* findParamRange(std::string_view name);

/// What name accepts, as the messages say it ("a finite number in [0, 1e+12]").
RUBBLE_API std::string describeParamRange(const ParamRange& range);

/// InvalidInput "<name> must be <range>, got <value>" when value is outside name's range (or name is
/// unknown).
RUBBLE_API Status checkParam(std::string_view name, long double value);
/// checkParam against a range of one's own (a Real or Integer range).
RUBBLE_API Status checkParam(const ParamRange& range, long double value);
/// checkParam for a Point or Direction parameter.
RUBBLE_API Status checkParam(std::string_view name, const Vec3& value);
/// checkParam for a value given as text (the CLI's): a value that is no number is refused the same way.
RUBBLE_API Status checkParamText(std::string_view name, std::string_view text);

/// The most pieces a fracture into `cells` cells repeated over `depth` levels may make: the sum over the
/// levels of max(2, cells)^level (a piece can be broken into every cell plus remainder islands).
RUBBLE_API long double piecesBound(int cells, int depth);
/// InvalidInput when piecesBound(cells, depth) exceeds kMaxTotalPieces, with both figures in the message.
RUBBLE_API Status checkPieceBudget(int cells, int depth);

} // namespace rubble
