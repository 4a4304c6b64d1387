// STL, read by Rubble: ASCII text with exact doubles and file:line errors, or binary facets (floats, widened
// exactly) checked against the header's count. Normals are not kept; exactly equal positions are welded (STL
// repeats every corner).
#include <bit>
#include <charconv>
#include <cmath>
#include <vector>

#include "io/MeshFormatReaders.hpp"
#include "io/PolygonTriangulation.hpp"
#include "io/ReaderSupport.hpp"
#include "io/TextTokens.hpp"

namespace rubble::io {

namespace {
using detail::lower;
using detail::parseError;

// Starts with "solid" and holds no control bytes but whitespace: ASCII (a binary header may start with
// "solid" too, but its numbers hold zero bytes).
bool isAsciiStl(const std::string& b) {
    if (b.size() < 5 || lower(b.substr(0, 5)) != "solid")
        return false;
    for (const char c : b) {
        const auto u = static_cast<unsigned char>(c);
        if (u < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\v' && c != '\f')
            return false;
    }
    return true;
}

// ASCII STL: solid / facet normal / outer loop / vertex x y z (three or more) / endloop / endfacet /
// endsolid, several solids allowed; keywords in any case.
Result<Mesh> readAsciiStl(const std::string& b, const std::string& name) {
    std::size_t pos = 0, line = 0;
    const char br = detail::lineBreakOf(b);
    std::vector<std::string> tok;
    auto fail = [&](const std::string& message) {
        return makeError(ErrorCode::ParseError, name + ":" + std::to_string(line) + ": " + message);
    };
    auto nextLine = [&]() {
        tok.clear();
        while (tok.empty() && pos < b.size()) {
            ++line;
            std::size_t end = b.find(br, pos);
            if (end == std::string::npos)
                end = b.size();
            for (std::string_view t : detail::tokenize(std::string_view(b.data() + pos, end - pos)))
                tok.emplace_back(t);
            pos = end + 1;
        }
        if (!tok.empty())
            tok[0] = lower(tok[0]);
        return !tok.empty();
    };
    auto shown = [](const std::string& t) { return "'" + t.substr(0, 40) + "'"; };
    Mesh m;
    detail::PositionWelder weld(m);
    bool inSolid = false;
    while (nextLine()) {
        if (!inSolid) {
            if (tok[0] != "solid")
                return fail("expected 'solid', got " + shown(tok[0]));
            inSolid = true;
            continue;
        }
        if (tok[0] == "endsolid") {
            inSolid = false;
            continue;
        }
        if (tok[0] != "facet")
            return fail("expected 'facet' or 'endsolid', got " + shown(tok[0]));
        if (!nextLine() || tok[0] != "outer" || tok.size() != 2 || lower(tok[1]) != "loop")
            return fail(tok.empty() ? std::string("the file ends inside a facet")
                                    : "expected 'outer loop', got " + shown(tok[0]));
        std::vector<Vec3> corners;
        while (nextLine() && tok[0] == "vertex") {
            if (tok.size() != 4)
                return fail("vertex needs 3 numbers, got " + std::to_string(tok.size() - 1));
            double c[3];
            for (int k = 0; k < 3; ++k) {
                const std::string& t = tok[static_cast<std::size_t>(k) + 1];
                const std::string axis(1, static_cast<char>('x' + k));
                const detail::NumberStatus s = detail::parseDouble(t, c[k]);
                if (s == detail::NumberStatus::NotANumber)
                    return fail("vertex: expected a number for " + axis + ", got " + shown(t));
                if (s == detail::NumberStatus::OutOfRange)
                    return fail("vertex: value " + shown(t) + " for " + axis + " is out of range");
            }
            corners.push_back({c[0], c[1], c[2]});
        }
        if (tok.empty())
            return fail("the file ends inside a facet");
        if (tok[0] != "endloop")
            return fail("expected 'vertex' or 'endloop', got " + shown(tok[0]));
        if (corners.size() < 3)
            return fail("facet has " + std::to_string(corners.size()) +
                        (corners.size() == 1 ? " vertex" : " vertices") + "; at least 3 are needed");
        if (!nextLine() || tok[0] != "endfacet")
            return fail(tok.empty() ? std::string("the file ends inside a facet")
                                    : "expected 'endfacet', got " + shown(tok[0]));
        std::vector<std::uint32_t> ids;
        for (const Vec3& p : corners)
            ids.push_back(weld.add(p));
        for (const auto& t : triangulatePolygon(corners))
            m.triangles.push_back({ids[t[0]], ids[t[1]], ids[t[2]]});
        if (m.positions.size() >= 0xFFFF'FFF0u)
            return fail("too many vertices");
    }
    if (inSolid)
        return fail("the file ends without 'endsolid' (truncated?)");
    if (m.triangles.empty())
        return parseError(name, "no triangles");
    return m;
}

// Binary STL: an 80-byte header, a facet count, then 50 bytes per facet (normal, three corners, attribute).
// Bytes after the last counted facet (padding some exporters add) are ignored.
Result<Mesh> readBinaryStl(const std::string& b, const std::string& name) {
    if (b.size() < 84)
        return parseError(name, "too short for a binary STL (" + std::to_string(b.size()) +
                                    " bytes; a binary STL has an 84-byte header)");
    const std::uint32_t count = detail::readU32(b, 80);
    const long double needed = 84.0L + 50.0L * count;
    if (count == 0 && b.size() > 84 && (b.size() - 84) % 50 == 0)
        return parseError(name, "binary STL header claims 0 triangles but " + std::to_string(b.size() - 84) +
                                    " bytes of facets (" + std::to_string((b.size() - 84) / 50) +
                                    " triangles) follow it");
    if (needed > static_cast<long double>(b.size()))
        return parseError(name, "binary STL header claims " + std::to_string(count) + " triangles (" +
                                    detail::bytesText(needed) + " bytes) but the file has " +
                                    std::to_string(b.size()) + " bytes");
    Mesh m;
    detail::PositionWelder weld(m);
    m.triangles.reserve(count);
    for (std::uint32_t f = 0; f < count; ++f) {
        const std::size_t at = 84 + 50 * static_cast<std::size_t>(f) + 12;
        Triangle t;
        for (std::size_t c = 0; c < 3; ++c) {
            double xyz[3];
            for (std::size_t k = 0; k < 3; ++k)
                xyz[k] = std::bit_cast<float>(detail::readU32(b, at + 12 * c + 4 * k));
            t[c] = weld.add({xyz[0], xyz[1], xyz[2]});
        }
        m.triangles.push_back(t);
    }
    if (m.triangles.empty())
        return parseError(name, "no triangles");
    return m;
}
} // namespace

Result<Mesh> parseStl(const std::string& bytes, const std::string& displayName) {
    if (isAsciiStl(bytes))
        return readAsciiStl(bytes, displayName);
    return readBinaryStl(bytes, displayName);
}

} // namespace rubble::io
