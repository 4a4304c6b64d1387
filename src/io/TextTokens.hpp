#pragma once
// Private to rubble_io: lines, tokens and numbers of the text formats Rubble reads itself (OBJ, OFF, PLY,
// STL).

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

namespace rubble::detail {

/// Blank characters that separate tokens on a line.
inline bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\r';
}

/// The first control byte of a line that no text format holds (a sign of a binary file), or -1.
inline int binaryByte(std::string_view line) {
    for (char ch : line) {
        const auto u = static_cast<unsigned char>(ch);
        if (u < 0x20 && ch != '\t' && ch != '\r' && ch != '\v' && ch != '\f')
            return u;
    }
    return -1;
}

/// The character that ends the lines of text: '\n' (LF or CR LF), or '\r' when its first line ends in a lone
/// CR (classic Mac OS line endings).
inline char lineBreakOf(std::string_view text) {
    const std::size_t cr = text.find('\r');
    if (cr == std::string_view::npos || cr + 1 >= text.size() || text[cr + 1] == '\n')
        return '\n';
    return text.find('\n') < cr ? '\n' : '\r';
}

/// The blank-separated tokens of a line.
inline std::vector<std::string_view> tokenize(std::string_view s) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && isSpace(s[i]))
            ++i;
        const std::size_t start = i;
        while (i < s.size() && !isSpace(s[i]))
            ++i;
        if (i > start)
            out.push_back(s.substr(start, i - start));
    }
    return out;
}

/// The text without leading and trailing blanks.
inline std::string_view trim(std::string_view s) {
    while (!s.empty() && isSpace(s.front()))
        s.remove_prefix(1);
    while (!s.empty() && isSpace(s.back()))
        s.remove_suffix(1);
    return s;
}

/// A token in quotes for a message, cut after 40 characters.
inline std::string quoted(std::string_view s) {
    constexpr std::size_t kMax = 40;
    return "'" + (s.size() > kMax ? std::string(s.substr(0, kMax)) + "..." : std::string(s)) + "'";
}

/// How a token read as a number.
enum class NumberStatus { Ok, NotANumber, OutOfRange };

/// A whole token as a double ("nan" and "inf" accepted; underflow becomes 0 or a subnormal).
inline NumberStatus parseDouble(std::string_view s, double& out) {
    if (!s.empty() && s.front() == '+')
        s.remove_prefix(1);
    if (s.empty() || s.front() == '+')
        return NumberStatus::NotANumber;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    if (ptr != s.data() + s.size())
        return NumberStatus::NotANumber;
    if (ec == std::errc::result_out_of_range) {
        const std::string copy(s);
        const double v = std::strtod(copy.c_str(), nullptr);
        if (std::isinf(v))
            return NumberStatus::OutOfRange;
        out = v;
        return NumberStatus::Ok;
    }
    return ec == std::errc() ? NumberStatus::Ok : NumberStatus::NotANumber;
}

} // namespace rubble::detail
