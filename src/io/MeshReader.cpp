// readMesh: OBJ and OFF through Rubble's readers, other formats through Assimp after checking size claims in
// their headers (Assimp trusts them and may try to allocate what a broken or hostile file claims).
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <unordered_map>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <nlohmann/json.hpp>

#include "io/FileBytes.hpp"
#include "io/PolygonTriangulation.hpp"
#include "io/SceneReaders.hpp"
#include "io/TextMeshReaders.hpp"
#include "rubble/MeshIO.hpp"
#include "rubble/SceneIO.hpp"

namespace rubble {

namespace {
std::string lower(std::string s) {
    for (char& c : s)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::uint32_t readU32(const std::string& b, std::size_t at) {
    const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at);
    return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
           std::uint32_t{p[3]} << 24;
}

std::uint16_t readU16(const std::string& b, std::size_t at) {
    const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at);
    return static_cast<std::uint16_t>(p[0] | p[1] << 8);
}

std::string bytesText(long double n) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.0Lf", n);
    return buf;
}

Error parseError(const std::string& name, const std::string& message) {
    return makeError(ErrorCode::ParseError, name + ": " + message);
}

// The face count a header declares, compared with what Assimp read (where: "file:line" or "file").
struct DeclaredFaces {
    std::uint64_t count = 0;
    std::string where;
    bool known = false;
};

// --- STL --------------------------------------------------------------------------------------------------

// Binary STL files with bytes after the last facet (padding some exporters add) are cut to their real size,
// because Assimp only recognises a binary STL whose size matches its triangle count exactly.
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

Status guardStl(const std::string& b, const std::string& name, std::size_t& truncateTo,
                DeclaredFaces& faces) {
    const bool solid = b.size() >= 5 && lower(b.substr(0, 5)) == "solid";
    if (b.size() < 84) {
        if (solid)
            return {};
        return parseError(name, "too short for a binary STL (" + std::to_string(b.size()) +
                                    " bytes; a binary STL has an 84-byte header)");
    }
    const std::uint32_t count = readU32(b, 80);
    const long double needed = 84.0L + 50.0L * count;
    if (needed == static_cast<long double>(b.size())) {
        faces = {count, name, true};
        return {};
    }
    if (solid) // ASCII STL ("solid ..."), read as text
        return {};
    if (count == 0 && (b.size() - 84) % 50 == 0)
        return parseError(name, "binary STL header claims 0 triangles but " + std::to_string(b.size() - 84) +
                                    " bytes of facets (" + std::to_string((b.size() - 84) / 50) +
                                    " triangles) follow it");
    faces = {count, name, true};
    if (needed > static_cast<long double>(b.size()))
        return parseError(name, "binary STL header claims " + std::to_string(count) + " triangles (" +
                                    bytesText(needed) + " bytes) but the file has " +
                                    std::to_string(b.size()) + " bytes");
    truncateTo = static_cast<std::size_t>(needed);
    return {};
}

struct PosKey {
    std::array<std::uint64_t, 3> bits;
    bool operator==(const PosKey&) const = default;
};
struct PosKeyHash {
    std::size_t operator()(const PosKey& k) const {
        return static_cast<std::size_t>(k.bits[0] * 0x9E3779B97F4A7C15ull ^
                                        k.bits[1] * 0xC2B2AE3D27D4EB4Full ^
                                        k.bits[2] * 0x165667B19E3779F9ull);
    }
};

PosKey keyOf(const Vec3& p) {
    PosKey k;
    const double c[3] = {p.x + 0.0, p.y + 0.0, p.z + 0.0};
    for (int i = 0; i < 3; ++i)
        std::memcpy(&k.bits[i], &c[i], sizeof(double));
    return k;
}

std::vector<std::string> words(std::string_view s) {
    std::vector<std::string> out;
    std::size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i])))
            ++i;
        const std::size_t st = i;
        while (i < s.size() && !std::isspace(static_cast<unsigned char>(s[i])))
            ++i;
        if (i > st)
            out.emplace_back(s.substr(st, i - st));
    }
    return out;
}

// ASCII STL, read by Rubble (exact doubles, file:line errors): solid / facet normal / outer loop / vertex x y
// z (three or more) / endloop / endfacet / endsolid, several solids allowed; keywords in any case. Normals
// are not kept; exactly equal positions are welded (STL repeats every corner).
Result<Mesh> readAsciiStl(const std::string& b, const std::string& name) {
    std::size_t pos = 0, line = 0;
    std::vector<std::string> tok;
    auto fail = [&](const std::string& message) {
        return makeError(ErrorCode::ParseError, name + ":" + std::to_string(line) + ": " + message);
    };
    auto nextLine = [&]() {
        tok.clear();
        while (tok.empty() && pos < b.size()) {
            ++line;
            std::size_t end = b.find('\n', pos);
            if (end == std::string::npos)
                end = b.size();
            tok = words(std::string_view(b.data() + pos, end - pos));
            pos = end + 1;
        }
        if (!tok.empty())
            tok[0] = lower(tok[0]);
        return !tok.empty();
    };
    auto shown = [](const std::string& t) { return "'" + t.substr(0, 40) + "'"; };
    Mesh m;
    std::unordered_map<PosKey, std::uint32_t, PosKeyHash> index;
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
                const char* first = t.data() + (t[0] == '+' ? 1 : 0);
                const auto [ptr, ec] = std::from_chars(first, t.data() + t.size(), c[k]);
                if (ptr != t.data() + t.size() || first == ptr)
                    return fail("vertex: expected a number for " +
                                std::string(1, static_cast<char>('x' + k)) + ", got " + shown(t));
                if (ec == std::errc::result_out_of_range) {
                    c[k] = std::strtod(first, nullptr);
                    if (std::isinf(c[k]))
                        return fail("vertex: value " + shown(t) + " for " +
                                    std::string(1, static_cast<char>('x' + k)) + " is out of range");
                }
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
        for (const Vec3& p : corners) {
            auto [it, inserted] = index.emplace(keyOf(p), static_cast<std::uint32_t>(m.positions.size()));
            if (inserted)
                m.positions.push_back(p);
            ids.push_back(it->second);
        }
        for (const auto& t : io::triangulatePolygon(corners))
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

// --- PLY --------------------------------------------------------------------------------------------------

int plyTypeSize(const std::string& t) {
    static const std::unordered_map<std::string, int> sizes = {
        {"char", 1},   {"int8", 1},    {"uchar", 1},  {"uint8", 1},  {"short", 2}, {"int16", 2},
        {"ushort", 2}, {"uint16", 2},  {"int", 4},    {"int32", 4},  {"uint", 4},  {"uint32", 4},
        {"float", 4},  {"float32", 4}, {"double", 8}, {"float64", 8}};
    const auto it = sizes.find(t);
    return it == sizes.end() ? 0 : it->second;
}

bool parseCount(const std::string& s, std::uint64_t& out) {
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && ptr == s.data() + s.size();
}

struct PlyProperty {
    std::string name;
    bool list = false;
};

struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::size_t line = 0;
    long double minBinary = 0; // bytes per element, at least
    std::size_t properties = 0;
    std::vector<PlyProperty> props;
};

// A parsed PLY header: the format, the elements and where the body starts.
struct PlyHeader {
    std::string format;
    std::vector<PlyElement> elements;
    std::size_t bodyPos = 0, bodyLine = 0;
};

Status guardPly(const std::string& b, const std::string& name, DeclaredFaces& faces, PlyHeader& header) {
    constexpr std::size_t kMaxHeader = 1 << 20;
    using Element = PlyElement;
    std::vector<Element> elements;
    std::string format;
    std::size_t pos = 0, line = 0;
    bool ended = false;
    while (pos < b.size() && pos < kMaxHeader) {
        ++line;
        std::size_t end = b.find('\n', pos);
        if (end == std::string::npos)
            end = b.size();
        const std::string_view ln(b.data() + pos, end - pos);
        pos = end + 1;
        const auto w = words(ln);
        if (line == 1) {
            if (w.size() != 1 || w[0] != "ply")
                return parseError(name, "not a PLY file (the first line is not 'ply')");
            continue;
        }
        if (w.empty() || w[0] == "comment" || w[0] == "obj_info")
            continue;
        const std::string where = name + ":" + std::to_string(line) + ": ";
        if (w[0] == "end_header") {
            ended = true;
            break;
        }
        if (w[0] == "format") {
            if (w.size() < 2 ||
                (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
                return makeError(ErrorCode::ParseError,
                                 where + "unknown PLY format '" + (w.size() > 1 ? w[1] : "") + "'");
            format = w[1];
        } else if (w[0] == "element") {
            Element e;
            e.line = line;
            if (w.size() != 3 || !parseCount(w[2], e.count))
                return makeError(ErrorCode::ParseError, where + "expected 'element <name> <count>'");
            e.name = w[1];
            elements.push_back(e);
        } else if (w[0] == "property") {
            if (elements.empty())
                return makeError(ErrorCode::ParseError, where + "property before any element");
            Element& e = elements.back();
            if (w.size() >= 2 && w[1] == "list") {
                if (w.size() != 5 || plyTypeSize(w[2]) == 0 || plyTypeSize(w[3]) == 0)
                    return makeError(ErrorCode::ParseError,
                                     where + "expected 'property list <count type> <item type> <name>'");
                e.minBinary += plyTypeSize(w[2]);
                e.props.push_back({w[4], true});
            } else {
                if (w.size() != 3 || plyTypeSize(w[1]) == 0)
                    return makeError(ErrorCode::ParseError, where + "expected 'property <type> <name>'");
                e.minBinary += plyTypeSize(w[1]);
                e.props.push_back({w[2], false});
            }
            ++e.properties;
        } else {
            return makeError(ErrorCode::ParseError, where + "unknown header keyword '" + w[0] + "'");
        }
    }
    if (!ended)
        return parseError(name, "PLY header has no 'end_header' line");
    if (format.empty())
        return parseError(name, "PLY header has no 'format' line");
    const long double body = pos >= b.size() ? 0.0L : static_cast<long double>(b.size() - pos);
    long double total = 0;
    for (const Element& e : elements)
        if (e.name == "face")
            faces = {e.count, name + ":" + std::to_string(e.line), true};
    for (const Element& e : elements) {
        const long double per = format == "ascii" ? std::max<long double>(1, 2.0L * e.properties)
                                                  : std::max<long double>(1, e.minBinary);
        total += per * static_cast<long double>(e.count);
        if (total > body + 1)
            return makeError(ErrorCode::ParseError, name + ":" + std::to_string(e.line) + ": header claims " +
                                                        std::to_string(e.count) + " '" + e.name +
                                                        "' elements (at least " + bytesText(total) +
                                                        " bytes of data) but only " + bytesText(body) +
                                                        " bytes follow the header");
    }
    header = {format, std::move(elements), pos, line};
    return {};
}

// ASCII PLY, read by Rubble (exact doubles, file:line errors): one element per line; vertex x, y, z and the
// face list vertex_indices (or vertex_index) are used, every other property is checked to be a number and
// ignored. Exactly equal positions are welded (exporters split vertices per face for normals and colours).
Result<Mesh> readAsciiPly(const std::string& b, const std::string& name, const PlyHeader& h) {
    std::size_t pos = h.bodyPos, line = h.bodyLine;
    auto fail = [&](const std::string& message) {
        return makeError(ErrorCode::ParseError, name + ":" + std::to_string(line) + ": " + message);
    };
    std::vector<std::string> tok;
    auto nextLine = [&]() {
        tok.clear();
        while (tok.empty() && pos < b.size()) {
            ++line;
            std::size_t end = b.find('\n', pos);
            if (end == std::string::npos)
                end = b.size();
            tok = words(std::string_view(b.data() + pos, end - pos));
            pos = end + 1;
        }
    };
    // 0: a number; 1: not a number; 2: beyond the double range (underflow gives 0 or a subnormal).
    auto number = [](const std::string& t, double& v) {
        const char* first = t.data() + (!t.empty() && t[0] == '+' ? 1 : 0);
        const auto [ptr, ec] = std::from_chars(first, t.data() + t.size(), v);
        if (ptr != t.data() + t.size() || first == t.data() + t.size())
            return 1;
        if (ec == std::errc::result_out_of_range) {
            v = std::strtod(first, nullptr);
            return std::isinf(v) ? 2 : 0;
        }
        return ec == std::errc() ? 0 : 1;
    };
    std::vector<Vec3> positions;
    std::vector<Triangle> triangles;
    std::size_t vertexCount = 0;
    for (const PlyElement& e : h.elements) {
        const bool isVertex = e.name == "vertex", isFace = e.name == "face";
        int xyz[3] = {-1, -1, -1};
        if (isVertex) {
            for (std::size_t k = 0; k < e.props.size(); ++k)
                for (int c = 0; c < 3; ++c)
                    if (!e.props[k].list && e.props[k].name == std::string(1, static_cast<char>('x' + c)))
                        xyz[c] = static_cast<int>(k);
            if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0) {
                line = e.line;
                return fail("the vertex element has no x, y and z properties");
            }
            vertexCount = static_cast<std::size_t>(e.count);
        }
        for (std::uint64_t i = 0; i < e.count; ++i) {
            nextLine();
            if (tok.empty())
                return fail("the file ends after " + std::to_string(i) + " of the " +
                            std::to_string(e.count) + " declared '" + e.name + "' elements");
            const std::string what = "'" + e.name + "' " + std::to_string(i);
            std::size_t t = 0;
            double c[3] = {0, 0, 0};
            std::vector<std::uint32_t> corners;
            for (std::size_t k = 0; k < e.props.size(); ++k) {
                const PlyProperty& p = e.props[k];
                std::uint64_t n = 1;
                if (p.list) {
                    if (t >= tok.size() || !parseCount(tok[t], n))
                        return fail(
                            what + ": expected the length of the list '" + p.name + "', got " +
                            (t < tok.size() ? "'" + tok[t].substr(0, 40) + "'" : "the end of the line"));
                    ++t;
                }
                if (n > tok.size() - t)
                    return fail(what + ": the line ends before its properties do (" +
                                std::to_string(tok.size()) + " numbers; truncated?)");
                const bool indices =
                    isFace && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
                for (std::uint64_t m = 0; m < n; ++m, ++t) {
                    double v = 0;
                    const int kind = number(tok[t], v);
                    if (kind == 1)
                        return fail(what + ": expected a number for '" + p.name + "', got '" +
                                    tok[t].substr(0, 40) + "'");
                    if (kind == 2)
                        return fail(what + ": value '" + tok[t].substr(0, 40) + "' for '" + p.name +
                                    "' is out of range");
                    for (int a = 0; a < 3; ++a)
                        if (isVertex && static_cast<int>(k) == xyz[a])
                            c[a] = v;
                    if (indices) {
                        if (!(v >= 0 && v < static_cast<double>(vertexCount)) || v != std::floor(v))
                            return fail(what + " refers to vertex " + tok[t].substr(0, 40) +
                                        " but there are " + std::to_string(vertexCount) +
                                        " (PLY indices start at 0)");
                        corners.push_back(static_cast<std::uint32_t>(v));
                    }
                }
                if (indices && corners.size() < 3)
                    return fail(what + " has " + std::to_string(corners.size()) +
                                (corners.size() == 1 ? " corner" : " corners") + "; at least 3 are needed");
            }
            if (t != tok.size())
                return fail(what + ": " + std::to_string(tok.size() - t) +
                            " more numbers than its properties need");
            if (isVertex)
                positions.push_back({c[0], c[1], c[2]});
            if (corners.size() == 3) {
                triangles.push_back({corners[0], corners[1], corners[2]});
            } else if (!corners.empty()) {
                std::vector<Vec3> pts;
                for (std::uint32_t v : corners)
                    pts.push_back(positions[v]);
                for (const auto& tri : io::triangulatePolygon(pts))
                    triangles.push_back({corners[tri[0]], corners[tri[1]], corners[tri[2]]});
            }
        }
    }
    nextLine();
    if (!tok.empty())
        return fail("unexpected '" + tok[0].substr(0, 40) +
                    "' after the declared elements (the header's counts do not match the file)");
    if (triangles.empty())
        return parseError(name, "no triangles");
    // Weld exactly equal positions (first occurrence wins); unreferenced vertices are dropped.
    Mesh m;
    std::unordered_map<PosKey, std::uint32_t, PosKeyHash> index;
    std::vector<std::uint32_t> remap(positions.size(), UINT32_MAX);
    for (Triangle& tri : triangles) {
        for (std::uint32_t& v : tri) {
            if (remap[v] == UINT32_MAX) {
                auto [it, inserted] =
                    index.emplace(keyOf(positions[v]), static_cast<std::uint32_t>(m.positions.size()));
                if (inserted)
                    m.positions.push_back(positions[v]);
                remap[v] = it->second;
            }
            v = remap[v];
        }
        m.triangles.push_back(tri);
    }
    return m;
}

// --- OFF --------------------------------------------------------------------------------------------------

Status guardOff(const std::string& b, const std::string& name) {
    // Tokens with their line numbers, comments skipped; only the first few are needed.
    std::vector<std::pair<std::string, std::size_t>> tok;
    std::size_t line = 1;
    for (std::size_t i = 0; i < b.size() && tok.size() < 6;) {
        const char c = b[i];
        if (c == '\n') {
            ++line;
            ++i;
        } else if (c == '#') {
            while (i < b.size() && b[i] != '\n')
                ++i;
        } else if (std::isspace(static_cast<unsigned char>(c))) {
            ++i;
        } else {
            const std::size_t st = i;
            while (i < b.size() && !std::isspace(static_cast<unsigned char>(b[i])) && b[i] != '#')
                ++i;
            tok.emplace_back(b.substr(st, std::min<std::size_t>(i - st, 64)), line);
        }
    }
    if (tok.empty() || tok[0].first.find("OFF") == std::string::npos)
        return parseError(name, "not an OFF file (it does not start with 'OFF')");
    std::size_t k = 1;
    if (tok[0].first.front() == 'n' || tok[0].first.find("nOFF") != std::string::npos)
        ++k; // dimension
    if (k < tok.size() && lower(tok[k].first) == "binary")
        return makeError(ErrorCode::Unsupported, name + ": binary OFF files are not supported");
    std::uint64_t nv = 0, nf = 0;
    if (k + 1 >= tok.size() || !parseCount(tok[k].first, nv) || !parseCount(tok[k + 1].first, nf))
        return makeError(ErrorCode::ParseError, name + ":" +
                                                    std::to_string(k < tok.size() ? tok[k].second : line) +
                                                    ": expected the vertex and face counts after 'OFF'");
    const long double needed = 6.0L * nv + 2.0L * nf; // "0 0 0\n" per vertex, "0\n" per face at least
    if (needed > static_cast<long double>(b.size()))
        return makeError(ErrorCode::ParseError,
                         name + ":" + std::to_string(tok[k].second) + ": header claims " +
                             std::to_string(nv) + " vertices and " + std::to_string(nf) +
                             " faces (at least " + bytesText(needed) + " bytes) but the file has " +
                             std::to_string(b.size()) + " bytes");
    return {};
}

// --- 3DS --------------------------------------------------------------------------------------------------

Status guard3dsChunks(const std::string& b, const std::string& name, std::size_t begin, std::size_t end,
                      int depth) {
    std::size_t at = begin;
    while (at + 6 <= end) {
        const std::uint16_t id = readU16(b, at);
        const std::uint32_t len = readU32(b, at + 2);
        if (len < 6 || len > end - at) {
            char buf[160];
            std::snprintf(buf, sizeof buf, "3DS chunk 0x%04X at byte %zu claims %u bytes but only %zu remain",
                          id, at, len, end - at);
            return parseError(name, buf);
        }
        // Descend into the containers that lead to the mesh data.
        if (depth < 4 && (id == 0x3D3D || id == 0x4100 || id == 0xB000))
            if (Status s = guard3dsChunks(b, name, at + 6, at + len, depth + 1); !s)
                return s;
        if (id == 0x4000 && depth < 4) { // named object: a 0-terminated name, then sub-chunks
            std::size_t p = at + 6;
            while (p < at + len && b[p] != '\0')
                ++p;
            if (Status s =
                    guard3dsChunks(b, name, std::min<std::size_t>(p + 1, at + len), at + len, depth + 1);
                !s)
                return s;
        }
        if ((id == 0x4110 || id == 0x4120 || id == 0x4140) && len >= 8) {
            const std::uint16_t n = readU16(b, at + 6);
            const std::size_t item = id == 0x4110 ? 12 : id == 0x4120 ? 8 : 8;
            if (8 + std::size_t{n} * item > len) {
                char buf[160];
                std::snprintf(buf, sizeof buf,
                              "3DS chunk 0x%04X at byte %zu claims %u items but holds only %u bytes", id, at,
                              unsigned{n}, len);
                return parseError(name, buf);
            }
        }
        at += len;
    }
    return {};
}

Status guard3ds(const std::string& b, const std::string& name) {
    if (b.size() < 6)
        return parseError(name, "too short for a 3DS file (" + std::to_string(b.size()) + " bytes)");
    const std::uint16_t id = readU16(b, 0);
    if (id != 0x4D4D) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "not a 3DS file (first chunk 0x%04X, expected 0x4D4D)", id);
        return parseError(name, buf);
    }
    const std::uint32_t len = readU32(b, 2);
    if (len < 6 || len > b.size())
        return parseError(name, "3DS main chunk claims " + std::to_string(len) + " bytes but the file has " +
                                    std::to_string(b.size()) + " bytes");
    return guard3dsChunks(b, name, 6, len, 0);
}

// --- glTF / GLB -------------------------------------------------------------------------------------------

long double base64Bytes(const std::string& uri) {
    const std::size_t comma = uri.find(',');
    if (comma == std::string::npos)
        return 0;
    std::size_t n = uri.size() - comma - 1, pad = 0;
    while (pad < 2 && n > pad && uri[uri.size() - 1 - pad] == '=')
        ++pad;
    return static_cast<long double>(n / 4 * 3) - static_cast<long double>(pad);
}

// Assimp's glTF parser and importer recurse once per JSON level and once per node level: deep files crash
// them.
constexpr std::size_t kMaxGltfJsonDepth = 256;
constexpr std::size_t kMaxGltfNodeDepth = 1024;

// The JSON's nesting depth stays within kMaxGltfJsonDepth (scanned before any parser sees the text).
Status guardJsonDepth(std::string_view text, const std::string& name) {
    std::size_t depth = 0;
    bool inString = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxGltfJsonDepth)
                return parseError(name, "its JSON is nested more than " + std::to_string(kMaxGltfJsonDepth) +
                                            " levels deep (at byte " + std::to_string(i) + ")");
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return {};
}

// Node children are valid indices, every node has at most one parent, there is no cycle, and the hierarchy
// is at most kMaxGltfNodeDepth deep (glTF's nodes form disjoint strict trees).
Status guardGltfNodes(const nlohmann::json& j, const std::string& name) {
    if (!j.contains("nodes") || !j["nodes"].is_array())
        return {};
    const nlohmann::json& nodes = j["nodes"];
    const std::size_t n = nodes.size();
    std::vector<std::size_t> parent(n, SIZE_MAX);
    for (std::size_t i = 0; i < n; ++i) {
        if (!nodes[i].is_object() || !nodes[i].contains("children"))
            continue;
        const nlohmann::json& children = nodes[i]["children"];
        if (!children.is_array())
            return parseError(name, "node " + std::to_string(i) + ": 'children' is not an array");
        for (const nlohmann::json& c : children) {
            if (!c.is_number_unsigned())
                return parseError(name,
                                  "node " + std::to_string(i) + " has a child that is not a node index");
            if (c.get<std::uint64_t>() >= n)
                return parseError(name, "node " + std::to_string(i) + " has child " +
                                            std::to_string(c.get<std::uint64_t>()) + " but there are only " +
                                            std::to_string(n) + " nodes");
            const auto k = c.get<std::size_t>();
            if (parent[k] != SIZE_MAX || k == i)
                return parseError(name, "node " + std::to_string(k) +
                                            " has more than one parent (glTF nodes form trees)");
            parent[k] = i;
        }
    }
    // Depth of every node by walking up to its root (memoised); a walk longer than n is a cycle.
    std::vector<std::size_t> depth(n, 0);
    std::vector<std::size_t> path;
    for (std::size_t i = 0; i < n; ++i) {
        path.clear();
        std::size_t k = i;
        while (k != SIZE_MAX && depth[k] == 0) {
            path.push_back(k);
            if (path.size() > n)
                return parseError(name, "node " + std::to_string(i) + " is its own ancestor (a cycle)");
            k = parent[k];
        }
        std::size_t d = k == SIZE_MAX ? 0 : depth[k];
        for (auto it = path.rbegin(); it != path.rend(); ++it) {
            depth[*it] = ++d;
            if (d > kMaxGltfNodeDepth)
                return parseError(name, "the node hierarchy is more than " +
                                            std::to_string(kMaxGltfNodeDepth) + " levels deep (node " +
                                            std::to_string(*it) + ")");
        }
    }
    return {};
}

Status guardGltfJson(const nlohmann::json& j, const std::filesystem::path& path, const std::string& name,
                     long double glbBinBytes) {
    using nlohmann::json;
    if (Status s = guardGltfNodes(j, name); !s)
        return s;
    auto count = [](const json& v, const char* key) -> long double {
        const auto it = v.find(key);
        if (it == v.end() || !it->is_number())
            return 0;
        return it->get<long double>();
    };
    std::vector<long double> bufferLen;
    if (j.contains("buffers") && j["buffers"].is_array())
        for (std::size_t i = 0; i < j["buffers"].size(); ++i) {
            const json& buf = j["buffers"][i];
            const long double claimed = count(buf, "byteLength");
            long double available = 0;
            if (buf.contains("uri") && buf["uri"].is_string()) {
                const std::string uri = buf["uri"].get<std::string>();
                if (uri.rfind("data:", 0) == 0) {
                    available = base64Bytes(uri);
                } else {
                    std::error_code ec;
                    const auto file = path.parent_path() / uri;
                    const auto size = std::filesystem::file_size(file, ec);
                    if (ec)
                        return parseError(name, "buffer " + std::to_string(i) + " refers to '" + uri +
                                                    "', which cannot be read");
                    available = static_cast<long double>(size);
                }
            } else {
                available = i == 0 ? glbBinBytes : 0;
            }
            if (claimed > available)
                return parseError(name, "buffer " + std::to_string(i) + " claims " + bytesText(claimed) +
                                            " bytes but only " + bytesText(available) + " are available");
            bufferLen.push_back(claimed);
        }
    std::vector<long double> viewLen;
    if (j.contains("bufferViews") && j["bufferViews"].is_array())
        for (std::size_t i = 0; i < j["bufferViews"].size(); ++i) {
            const json& v = j["bufferViews"][i];
            const long double b = count(v, "buffer");
            const long double end = count(v, "byteOffset") + count(v, "byteLength");
            if (b < 0 || b >= static_cast<long double>(bufferLen.size()) ||
                end > bufferLen[static_cast<std::size_t>(b)])
                return parseError(name, "buffer view " + std::to_string(i) + " lies outside its buffer");
            viewLen.push_back(count(v, "byteLength"));
        }
    if (j.contains("accessors") && j["accessors"].is_array())
        for (std::size_t i = 0; i < j["accessors"].size(); ++i) {
            const json& a = j["accessors"][i];
            const long double n = count(a, "count");
            const int ct = static_cast<int>(count(a, "componentType"));
            const int cs = ct == 5120 || ct == 5121 ? 1 : ct == 5122 || ct == 5123 ? 2 : 4;
            static const std::unordered_map<std::string, int> comps = {
                {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT2", 4}, {"MAT3", 9}, {"MAT4", 16}};
            int nc = 1;
            if (a.contains("type") && a["type"].is_string()) {
                const auto it = comps.find(a["type"].get<std::string>());
                nc = it == comps.end() ? 1 : it->second;
            }
            const long double elem = static_cast<long double>(cs) * nc;
            if (!a.contains("bufferView")) {
                if (n * elem > 256.0L * 1024 * 1024)
                    return parseError(name, "accessor " + std::to_string(i) + " claims " + bytesText(n) +
                                                " elements without any data");
                continue;
            }
            const long double vi = count(a, "bufferView");
            if (vi < 0 || vi >= static_cast<long double>(viewLen.size()))
                return parseError(name, "accessor " + std::to_string(i) + " refers to a missing buffer view");
            long double stride = elem;
            const json& view = j["bufferViews"][static_cast<std::size_t>(vi)];
            if (count(view, "byteStride") > 0)
                stride = count(view, "byteStride");
            const long double needed = n > 0 ? count(a, "byteOffset") + stride * (n - 1) + elem : 0;
            if (needed > viewLen[static_cast<std::size_t>(vi)])
                return parseError(name, "accessor " + std::to_string(i) + " claims " + bytesText(n) +
                                            " elements (" + bytesText(needed) +
                                            " bytes) but its buffer view has " +
                                            bytesText(viewLen[static_cast<std::size_t>(vi)]) + " bytes");
        }
    return {};
}

Status guardGltf(const std::string& b, const std::filesystem::path& path, const std::string& name, bool glb) {
    std::string jsonText;
    long double binBytes = 0;
    if (glb) {
        if (b.size() < 20 || b.compare(0, 4, "glTF") != 0)
            return parseError(name, "not a GLB file (missing the 'glTF' magic)");
        const std::uint32_t total = readU32(b, 8);
        if (total > b.size())
            return parseError(name, "GLB header claims " + std::to_string(total) +
                                        " bytes but the file has " + std::to_string(b.size()) + " bytes");
        std::size_t at = 12;
        while (at + 8 <= total) {
            const std::uint32_t len = readU32(b, at), type = readU32(b, at + 4);
            if (len > total - at - 8)
                return parseError(name, "GLB chunk at byte " + std::to_string(at) + " claims " +
                                            std::to_string(len) + " bytes but only " +
                                            std::to_string(total - at - 8) + " remain");
            if (type == 0x4E4F534Au && jsonText.empty())
                jsonText = b.substr(at + 8, len);
            else if (type == 0x004E4942u && binBytes == 0)
                binBytes = len;
            at += 8 + len;
        }
        if (jsonText.empty())
            return parseError(name, "GLB file has no JSON chunk");
    } else {
        jsonText = b;
    }
    if (Status s = guardJsonDepth(jsonText, name); !s)
        return s;
    const nlohmann::json j = nlohmann::json::parse(jsonText, nullptr, false);
    if (j.is_discarded() || !j.is_object())
        return parseError(name, "not a glTF file (its JSON is malformed)");
    try {
        return guardGltfJson(j, path, name, binBytes);
    } catch (const std::exception& e) {
        return parseError(name, std::string("malformed glTF: ") + e.what());
    }
}

// --- Assimp -----------------------------------------------------------------------------------------------

// An Assimp scene read from a file (or memory), owned with its importer.
struct AssimpScene {
    Assimp::Importer importer;
    const aiScene* scene = nullptr;
};

Status importWithAssimp(AssimpScene& out, const std::filesystem::path& path, const std::string& name,
                        const DeclaredFaces& declared, const std::string* memory, const char* hint) {
    out.importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    try {
        // Polygons are triangulated below, not by aiProcess_Triangulate: Debian's Assimp is built with its
        // assertions on, and TriangulateProcess aborts the process on some malformed polygons.
        const unsigned flags = aiProcess_ValidateDataStructure | aiProcess_JoinIdenticalVertices;
        out.scene = memory ? out.importer.ReadFileFromMemory(memory->data(), memory->size(), flags, hint)
                           : out.importer.ReadFile(path.string(), flags);
    } catch (const std::exception& e) {
        return parseError(name, e.what());
    }
    const aiScene* scene = out.scene;
    if (!scene) {
        std::string why = out.importer.GetErrorString();
        while (!why.empty() && (why.back() == '\n' || why.back() == ' ' || why.back() == '.'))
            why.pop_back();
        return parseError(name, why.empty() ? "Assimp could not read the file" : why);
    }
    if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE || !scene->mRootNode)
        return parseError(name, "the file describes an incomplete scene (no mesh data)");
    if (declared.known) {
        std::uint64_t read = 0;
        for (unsigned i = 0; i < scene->mNumMeshes; ++i)
            read += scene->mMeshes[i]->mNumFaces;
        if (read != declared.count)
            return makeError(ErrorCode::ParseError, declared.where + ": the header declares " +
                                                        std::to_string(declared.count) + " faces but " +
                                                        std::to_string(read) + " were read");
    }
    return {};
}

// Builds one Mesh from the meshes of the nodes it is given (positions welded exactly).
class AssimpMeshBuilder {
public:
    // materialIds: Assimp material index -> material id (empty: no materials).
    AssimpMeshBuilder(const aiScene* scene, std::vector<std::uint32_t> materialIds)
        : scene_(scene), materialIds_(std::move(materialIds)) {
        for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
            anyNormals_ = anyNormals_ || scene->mMeshes[i]->HasNormals();
            anyUvs_ = anyUvs_ || scene->mMeshes[i]->HasTextureCoords(0);
        }
    }

    // Appends the triangles of node's meshes transformed by xf.
    void addNode(const aiNode* node, const aiMatrix4x4& xf) {
        aiMatrix3x3 normalXf(xf);
        normalXf.Inverse().Transpose();
        const bool mirrored = aiMatrix3x3(xf).Determinant() < 0;
        for (unsigned k = 0; k < node->mNumMeshes; ++k) {
            if (node->mMeshes[k] >= scene_->mNumMeshes)
                continue;
            addMesh(scene_->mMeshes[node->mMeshes[k]], xf, normalXf, mirrored);
        }
    }

    Mesh& mesh() { return m_; }

private:
    void addMesh(const aiMesh* am, const aiMatrix4x4& xf, const aiMatrix3x3& normalXf, bool mirrored) {
        std::vector<std::array<unsigned, 3>> corners;
        for (unsigned f = 0; f < am->mNumFaces; ++f) {
            const aiFace& face = am->mFaces[f];
            if (face.mNumIndices < 3 || !face.mIndices)
                continue; // points and lines
            bool inRange = true;
            for (unsigned c = 0; c < face.mNumIndices; ++c)
                inRange = inRange && face.mIndices[c] < am->mNumVertices;
            if (!inRange)
                continue;
            if (face.mNumIndices == 3) {
                corners.push_back({face.mIndices[0], face.mIndices[1], face.mIndices[2]});
                continue;
            }
            std::vector<Vec3> pts;
            for (unsigned c = 0; c < face.mNumIndices; ++c) {
                const aiVector3D& p = am->mVertices[face.mIndices[c]];
                pts.push_back({p.x, p.y, p.z});
            }
            for (const auto& t : io::triangulatePolygon(pts))
                corners.push_back({face.mIndices[t[0]], face.mIndices[t[1]], face.mIndices[t[2]]});
        }
        for (std::array<unsigned, 3> ids : corners) {
            if (mirrored)
                std::swap(ids[1], ids[2]);
            Triangle tri;
            bool ok = true;
            for (int c = 0; c < 3; ++c) {
                if (ids[c] >= am->mNumVertices) {
                    ok = false;
                    break;
                }
                const aiVector3D p = xf * am->mVertices[ids[c]];
                const Vec3 v{p.x, p.y, p.z};
                auto [it, inserted] =
                    index_.emplace(keyOf(v), static_cast<std::uint32_t>(m_.positions.size()));
                if (inserted)
                    m_.positions.push_back(v);
                tri[c] = it->second;
            }
            if (!ok)
                continue;
            m_.triangles.push_back(tri);
            if (anyNormals_) {
                for (int c = 0; c < 3; ++c) {
                    if (am->HasNormals()) {
                        const aiVector3D n = normalXf * am->mNormals[ids[c]];
                        m_.normals.push_back(normalized(Vec3{n.x, n.y, n.z}));
                    } else {
                        m_.normals.push_back(normalized(m_.triangleNormal(m_.triangles.size() - 1)));
                    }
                }
            }
            if (anyUvs_)
                for (int c = 0; c < 3; ++c) {
                    if (am->HasTextureCoords(0)) {
                        const aiVector3D t = am->mTextureCoords[0][ids[c]];
                        m_.uvs.push_back({t.x, t.y});
                    } else {
                        m_.uvs.push_back({});
                    }
                }
            if (!materialIds_.empty())
                m_.materials.push_back(
                    am->mMaterialIndex < materialIds_.size() ? materialIds_[am->mMaterialIndex] : 0u);
        }
    }

    const aiScene* scene_;
    std::vector<std::uint32_t> materialIds_;
    bool anyNormals_ = false, anyUvs_ = false;
    Mesh m_;
    std::unordered_map<PosKey, std::uint32_t, PosKeyHash> index_;
};

std::string nodeName(const aiNode* node) {
    return node->mName.C_Str();
}

Result<Mesh> readWithAssimp(const std::filesystem::path& path, const std::string& name,
                            const DeclaredFaces& declared, const std::string* memory = nullptr,
                            const char* hint = "") {
    AssimpScene imported;
    if (Status s = importWithAssimp(imported, path, name, declared, memory, hint); !s)
        return s.error();
    const aiScene* scene = imported.scene;
    bool useMaterials = false;
    std::vector<std::string> materialNames;
    std::vector<std::uint32_t> materialIds;
    for (unsigned i = 0; i < scene->mNumMaterials; ++i) {
        aiString s;
        scene->mMaterials[i]->Get(AI_MATKEY_NAME, s);
        materialNames.emplace_back(s.C_Str());
        materialIds.push_back(i);
        useMaterials =
            useMaterials || (materialNames.back() != AI_DEFAULT_MATERIAL_NAME && scene->mNumMaterials > 0);
    }
    useMaterials = useMaterials && scene->mNumMaterials > 1;
    if (!useMaterials)
        materialIds.clear();

    // Every node's meshes but collision-only nodes (glTF "-convcolonly" children of pre-fractured pieces).
    AssimpMeshBuilder builder(scene, materialIds);
    std::vector<std::pair<const aiNode*, aiMatrix4x4>> stack{
        {scene->mRootNode, scene->mRootNode->mTransformation}};
    while (!stack.empty()) {
        const auto [node, xf] = stack.back();
        stack.pop_back();
        for (unsigned c = 0; c < node->mNumChildren; ++c)
            stack.emplace_back(node->mChildren[c], xf * node->mChildren[c]->mTransformation);
        if (!isCollisionName(nodeName(node)))
            builder.addNode(node, xf);
    }
    Mesh& m = builder.mesh();
    if (m.triangles.empty())
        return parseError(name, "no triangles");
    if (useMaterials)
        m.materialNames = std::move(materialNames);
    return std::move(m);
}

// The materials of an Assimp scene (base colour and base colour texture) and the material id of each.
void readAssimpMaterials(const aiScene* scene, const std::filesystem::path& folder, AssetScene& out,
                         std::vector<std::uint32_t>& ids, std::vector<std::string>& names) {
    for (unsigned i = 0; i < scene->mNumMaterials; ++i) {
        const aiMaterial* am = scene->mMaterials[i];
        aiString s;
        am->Get(AI_MATKEY_NAME, s);
        AssetMaterial mat;
        mat.name = s.C_Str();
        aiColor4D colour;
        if (am->Get(AI_MATKEY_BASE_COLOR, colour) == aiReturn_SUCCESS ||
            am->Get(AI_MATKEY_COLOR_DIFFUSE, colour) == aiReturn_SUCCESS)
            mat.baseColor = {colour.r, colour.g, colour.b};
        aiString texture;
        if (am->GetTexture(aiTextureType_BASE_COLOR, 0, &texture) == aiReturn_SUCCESS ||
            am->GetTexture(aiTextureType_DIFFUSE, 0, &texture) == aiReturn_SUCCESS) {
            TextureMap map;
            map.slot = "map_Kd";
            const std::string uri = texture.C_Str();
            if (const aiTexture* embedded = scene->GetEmbeddedTexture(uri.c_str())) {
                if (embedded->mHeight == 0) { // compressed image bytes (PNG, JPEG)
                    map.bytes.assign(reinterpret_cast<const char*>(embedded->pcData), embedded->mWidth);
                    const std::string hint = embedded->achFormatHint;
                    map.extension = "." + (hint.empty() ? std::string("png") : lower(hint));
                    mat.maps.push_back(std::move(map));
                } else {
                    out.warnings.push_back("material '" + mat.name +
                                           "': uncompressed embedded texture skipped");
                }
            } else if (!uri.empty()) {
                map.file = (folder / uri).lexically_normal();
                std::error_code ec;
                if (!std::filesystem::exists(map.file, ec))
                    out.warnings.push_back("material '" + mat.name + "': image " + map.file.string() +
                                           " not found");
                mat.maps.push_back(std::move(map));
            }
        }
        names.push_back(mat.name);
        ids.push_back(mat.name == kInteriorMaterialName ? kInteriorMaterial : i);
        out.materials.push_back(std::move(mat));
    }
}

// A glTF/GLB file (already guarded) as a scene: one object per node with a mesh, collision nodes attached to
// their nearest non-collision ancestor object.
Result<AssetScene> readSceneWithAssimp(const std::filesystem::path& path, const std::string& name) {
    AssimpScene imported;
    if (Status s = importWithAssimp(imported, path, name, {}, nullptr, ""); !s)
        return s.error();
    const aiScene* scene = imported.scene;
    AssetScene out;
    std::vector<std::uint32_t> ids;
    std::vector<std::string> names;
    readAssimpMaterials(scene, path.parent_path(), out, ids, names);
    if (ids.empty())
        ids.push_back(0);
    struct Visit {
        const aiNode* node;
        aiMatrix4x4 xf;
        int object; // index of the nearest ancestor object (-1: none)
    };
    // Depth-first in file order (children pushed in reverse).
    std::vector<Visit> stack{{scene->mRootNode, scene->mRootNode->mTransformation, -1}};
    while (!stack.empty()) {
        const Visit v = stack.back();
        stack.pop_back();
        int object = v.object;
        if (v.node->mNumMeshes > 0) {
            AssimpMeshBuilder builder(scene, ids);
            builder.addNode(v.node, v.xf);
            Mesh& m = builder.mesh();
            if (!m.triangles.empty()) {
                m.materialNames = names;
                const std::string nm = nodeName(v.node);
                if (isCollisionName(nm) && v.object >= 0) {
                    Mesh part = std::move(m);
                    part.materials.clear();
                    part.materialNames.clear();
                    out.objects[static_cast<std::size_t>(v.object)].collision.push_back(std::move(part));
                } else {
                    out.objects.push_back({nm, std::move(m), {}, v.object});
                    object = static_cast<int>(out.objects.size()) - 1;
                }
            }
        }
        for (unsigned c = v.node->mNumChildren; c-- > 0;)
            stack.push_back({v.node->mChildren[c], v.xf * v.node->mChildren[c]->mTransformation, object});
    }
    if (out.objects.empty())
        return parseError(name, "no triangles");
    return out;
}
} // namespace

namespace io {
Result<Mesh> parseAsciiPly(const std::string& bytes, const std::string& displayName) {
    DeclaredFaces declared;
    PlyHeader header;
    if (Status s = guardPly(bytes, displayName, declared, header); !s)
        return s.error();
    if (header.format != "ascii")
        return makeError(ErrorCode::Unsupported, displayName + ": not an ASCII PLY file");
    return readAsciiPly(bytes, displayName, header);
}

Result<Mesh> parseAsciiStl(const std::string& bytes, const std::string& displayName) {
    return readAsciiStl(bytes, displayName);
}

Result<AssetScene> readGltfScene(const std::filesystem::path& path) {
    const std::string name = io::displayName(path);
    {
        auto bytes = io::readFileBytes(path);
        if (!bytes)
            return bytes.error();
        if (bytes.value().empty())
            return parseError(name, "no triangles (the file is empty)");
        if (Status s = guardGltf(bytes.value(), path, name, lower(path.extension().string()) == ".glb"); !s)
            return s.error();
    }
    return readSceneWithAssimp(path, name);
}
} // namespace io

const std::vector<std::string>& supportedMeshExtensions() {
    static const std::vector<std::string> ext = {".obj", ".off", ".stl", ".ply", ".3ds", ".gltf", ".glb"};
    return ext;
}

Result<Mesh> readMesh(const std::filesystem::path& path) {
    const std::string name = io::displayName(path);
    const std::string ext = lower(path.extension().string());
    if (ext == ".obj")
        return readObj(path);
    const auto& all = supportedMeshExtensions();
    if (std::find(all.begin(), all.end(), ext) == all.end()) {
        std::string list;
        for (const auto& e : all)
            list += (list.empty() ? "" : ", ") + e;
        return makeError(ErrorCode::Unsupported,
                         name + ": unsupported mesh format '" + ext + "' (supported: " + list + ")");
    }
    Status guard;
    DeclaredFaces declared;
    std::string truncated; // a binary STL cut to its real size, read from memory
    {
        auto bytes = io::readFileBytes(path);
        if (!bytes)
            return bytes.error();
        const std::string& b = bytes.value();
        if (b.empty())
            return parseError(name, "no triangles (the file is empty)");
        if (ext == ".off") {
            if (Status s = guardOff(b, name); !s)
                return s.error();
            return parseOff(b, name);
        }
        std::size_t truncateTo = 0;
        if (ext == ".stl") {
            if (isAsciiStl(b))
                return readAsciiStl(b, name);
            guard = guardStl(b, name, truncateTo, declared);
            if (guard && truncateTo > 0 && truncateTo < b.size())
                truncated = b.substr(0, truncateTo);
        } else if (ext == ".ply") {
            PlyHeader header;
            guard = guardPly(b, name, declared, header);
            if (guard && header.format == "ascii")
                return readAsciiPly(b, name, header);
        } else if (ext == ".3ds")
            guard = guard3ds(b, name);
        else
            guard = guardGltf(b, path, name, ext == ".glb");
    }
    if (!guard)
        return guard.error();
    if (!truncated.empty())
        return readWithAssimp(path, name, declared, &truncated, "stl");
    return readWithAssimp(path, name, declared);
}

} // namespace rubble
