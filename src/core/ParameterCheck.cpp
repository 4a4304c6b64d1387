#include "rubble/core/ParameterCheck.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace rubble {

namespace {

/// A number as the messages print it: 6 significant digits, or whole numbers that need more in full.
std::string numberText(long double v) {
    if (std::isnan(v))
        return "nan";
    if (std::isinf(v))
        return v > 0 ? "inf" : "-inf";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6Lg", v);
    if (v == std::floor(v) && std::fabs(v) < 1e20L && std::strtold(buf, nullptr) != v)
        std::snprintf(buf, sizeof buf, "%.0Lf", v);
    return buf;
}

std::string vectorText(const Vec3& v) {
    return "(" + numberText(v.x) + ", " + numberText(v.y) + ", " + numberText(v.z) + ")";
}

Status refuse(const ParamRange& range, const std::string& got) {
    return makeError(ErrorCode::InvalidInput,
                     std::string(range.name) + " must be " + describeParamRange(range) + ", got " + got);
}

Status unknown(std::string_view name) {
    return makeError(ErrorCode::InvalidInput, "unknown parameter '" + std::string(name) + "'");
}

bool inRange(const ParamRange& range, long double v) {
    if (!std::isfinite(v) || v > range.hi || v < range.lo || (range.loOpen && v == range.lo))
        return false;
    return range.kind != ParamKind::Integer || v == std::floor(v);
}

} // namespace

const ParamRange* findParamRange(std::string_view name) {
    for (const ParamRange& r : kParamRanges)
        if (r.name == name)
            return &r;
    return nullptr;
}

std::string describeParamRange(const ParamRange& range) {
    const std::string interval =
        (range.loOpen ? "(" : "[") + numberText(range.lo) + ", " + numberText(range.hi) + "]";
    switch (range.kind) {
    case ParamKind::Real:
        return "a finite number in " + interval;
    case ParamKind::Integer:
        return "a whole number in " + interval;
    case ParamKind::Point:
        return "3 finite numbers";
    case ParamKind::Direction:
        return "3 finite numbers, not all 0";
    }
    return {};
}

Status checkParam(std::string_view name, long double value) {
    const ParamRange* range = findParamRange(name);
    if (!range || range->kind == ParamKind::Point || range->kind == ParamKind::Direction)
        return unknown(name);
    return checkParam(*range, value);
}

Status checkParam(const ParamRange& range, long double value) {
    if (!inRange(range, value))
        return refuse(range, numberText(value));
    return {};
}

Status checkParam(std::string_view name, const Vec3& value) {
    const ParamRange* range = findParamRange(name);
    if (!range || (range->kind != ParamKind::Point && range->kind != ParamKind::Direction))
        return unknown(name);
    if (!isFinite(value) || (range->kind == ParamKind::Direction && value == Vec3{}))
        return refuse(*range, vectorText(value));
    return {};
}

Status checkParamText(std::string_view name, std::string_view text) {
    const ParamRange* range = findParamRange(name);
    if (!range)
        return unknown(name);
    const std::string s(text);
    const Status notNumber = refuse(*range, "'" + s + "'");
    if (range->kind == ParamKind::Point || range->kind == ParamKind::Direction) {
        Vec3 v;
        double* out[3] = {&v.x, &v.y, &v.z};
        const char* p = s.c_str();
        for (int i = 0; i < 3; ++i) {
            char* end = nullptr;
            *out[i] = std::strtod(p, &end);
            if (end == p)
                return notNumber;
            p = end;
            while (*p == ' ')
                ++p;
            if (i < 2 && *p++ != ',')
                return notNumber;
        }
        return *p == '\0' ? checkParam(name, v) : notNumber;
    }
    // Whole numbers in decimal digits only: "1e3" or "0x10" for a seed is more likely a slip than meant.
    const std::size_t digits = !s.empty() && (s[0] == '-' || s[0] == '+') ? 1 : 0;
    if (range->kind == ParamKind::Integer &&
        (s.size() == digits || s.find_first_not_of("0123456789", digits) != std::string::npos))
        return notNumber;
    char* end = nullptr;
    const long double v = std::strtold(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || std::isspace(static_cast<unsigned char>(s[0])))
        return notNumber;
    return checkParam(name, v);
}

long double piecesBound(int cells, int depth) {
    const long double k = std::max(2, cells);
    long double total = 0, level = 1;
    for (int l = 1; l <= depth; ++l) {
        level *= k;
        total += level;
    }
    return total;
}

Status checkPieceBudget(int cells, int depth) {
    const long double n = piecesBound(cells, depth);
    if (n <= kMaxTotalPieces)
        return {};
    return makeError(ErrorCode::InvalidInput, "cells " + std::to_string(cells) + " and depth " +
                                                  std::to_string(depth) + " may make up to " + numberText(n) +
                                                  " pieces, more than the " + numberText(kMaxTotalPieces) +
                                                  " allowed: lower cells or depth");
}

} // namespace rubble
