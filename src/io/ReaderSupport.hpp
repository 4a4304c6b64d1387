#pragma once
// Private to rubble_io: small helpers shared by the mesh readers (bytes, messages, welding).

#include <array>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <unordered_map>

#include "rubble/core/Result.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// The text in lower case (ASCII).
inline std::string lower(std::string s) {
    for (char& c : s)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

/// A little-endian unsigned integer of n bytes at byte `at`.
inline std::uint64_t readLittle(const std::string& b, std::size_t at, int n) {
    std::uint64_t v = 0;
    for (int i = n - 1; i >= 0; --i)
        v = v << 8 | static_cast<unsigned char>(b[at + static_cast<std::size_t>(i)]);
    return v;
}

inline std::uint32_t readU32(const std::string& b, std::size_t at) {
    return static_cast<std::uint32_t>(readLittle(b, at, 4));
}

inline std::uint16_t readU16(const std::string& b, std::size_t at) {
    return static_cast<std::uint16_t>(readLittle(b, at, 2));
}

/// A whole token as an unsigned count.
inline bool parseCount(std::string_view s, std::uint64_t& out) {
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && ptr == s.data() + s.size();
}

/// A byte count (possibly beyond 64 bits) as digits.
inline std::string bytesText(long double n) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.0Lf", n);
    return buf;
}

/// A ParseError naming the file.
inline Error parseError(const std::string& name, const std::string& message) {
    return makeError(ErrorCode::ParseError, name + ": " + message);
}

/// Welds exactly equal positions (+0 and -0 alike) into one vertex, first occurrence first.
class PositionWelder {
public:
    explicit PositionWelder(Mesh& mesh) : mesh_(mesh) {}

    std::uint32_t add(const Vec3& p) {
        Key k;
        const double c[3] = {p.x + 0.0, p.y + 0.0, p.z + 0.0};
        for (int i = 0; i < 3; ++i)
            std::memcpy(&k.bits[static_cast<std::size_t>(i)], &c[i], sizeof(double));
        auto [it, inserted] = index_.emplace(k, static_cast<std::uint32_t>(mesh_.positions.size()));
        if (inserted)
            mesh_.positions.push_back(p);
        return it->second;
    }

private:
    struct Key {
        std::array<std::uint64_t, 3> bits;
        bool operator==(const Key&) const = default;
    };
    struct KeyHash {
        std::size_t operator()(const Key& k) const {
            return static_cast<std::size_t>(k.bits[0] * 0x9E3779B97F4A7C15ull ^
                                            k.bits[1] * 0xC2B2AE3D27D4EB4Full ^
                                            k.bits[2] * 0x165667B19E3779F9ull);
        }
    };
    Mesh& mesh_;
    std::unordered_map<Key, std::uint32_t, KeyHash> index_;
};

} // namespace rubble::detail
