// PLY, read by Rubble: the header is checked against the file size, then an ASCII or binary (either byte
// order) body is read exactly. Vertex x, y, z and the face list vertex_indices (or vertex_index) are used;
// every other property is read and ignored. Exactly equal positions are welded (exporters split vertices per
// face).
#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <unordered_map>
#include <vector>

#include "io/MeshFormatReaders.hpp"
#include "io/PolygonTriangulation.hpp"
#include "io/ReaderSupport.hpp"
#include "io/TextTokens.hpp"

namespace rubble::io {

namespace {
using detail::bytesText;
using detail::parseCount;
using detail::parseError;

// Size in bytes of a PLY scalar type, 0 if unknown.
int typeSize(const std::string& t) {
    static const std::unordered_map<std::string, int> sizes = {
        {"char", 1},   {"int8", 1},    {"uchar", 1},  {"uint8", 1},  {"short", 2}, {"int16", 2},
        {"ushort", 2}, {"uint16", 2},  {"int", 4},    {"int32", 4},  {"uint", 4},  {"uint32", 4},
        {"float", 4},  {"float32", 4}, {"double", 8}, {"float64", 8}};
    const auto it = sizes.find(t);
    return it == sizes.end() ? 0 : it->second;
}

bool isFloatType(const std::string& t) {
    return t == "float" || t == "float32" || t == "double" || t == "float64";
}

bool isSignedType(const std::string& t) {
    return t == "char" || t == "int8" || t == "short" || t == "int16" || t == "int" || t == "int32";
}

struct Property {
    std::string name;
    std::string type;      // item type
    std::string countType; // list length type; empty for a scalar
    bool list() const { return !countType.empty(); }
};

struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::size_t line = 0;
    long double minBinary = 0; // bytes per element, at least
    std::vector<Property> props;
};

struct Header {
    enum class Format { Ascii, Little, Big } format = Format::Ascii;
    std::vector<Element> elements;
    std::size_t bodyPos = 0, bodyLine = 0;
};

Result<Header> parseHeader(const std::string& b, const std::string& name) {
    constexpr std::size_t kMaxHeader = 1 << 20;
    Header h;
    bool ended = false, formatSeen = false;
    std::size_t pos = 0, line = 0;
    const char br = detail::lineBreakOf(std::string_view(b).substr(0, 64));
    while (pos < b.size() && pos < kMaxHeader) {
        ++line;
        std::size_t end = b.find(br, pos);
        if (end == std::string::npos)
            end = b.size();
        const auto w = detail::tokenize(std::string_view(b.data() + pos, end - pos));
        pos = end + 1;
        if (line == 1) {
            if (w.size() != 1 || w[0] != "ply")
                return parseError(name, "not a PLY file (the first line is not 'ply')");
            continue;
        }
        if (w.empty() || w[0] == "comment" || w[0] == "obj_info")
            continue;
        const std::string where = name + ":" + std::to_string(line) + ": ";
        auto fail = [&](const std::string& m) { return makeError(ErrorCode::ParseError, where + m); };
        if (w[0] == "end_header") {
            ended = true;
            break;
        }
        if (w[0] == "format") {
            if (w.size() >= 2 && w[1] == "ascii")
                h.format = Header::Format::Ascii;
            else if (w.size() >= 2 && w[1] == "binary_little_endian")
                h.format = Header::Format::Little;
            else if (w.size() >= 2 && w[1] == "binary_big_endian")
                h.format = Header::Format::Big;
            else
                return fail("unknown PLY format '" + (w.size() > 1 ? std::string(w[1]) : "") + "'");
            formatSeen = true;
        } else if (w[0] == "element") {
            Element e;
            e.line = line;
            if (w.size() != 3 || !parseCount(w[2], e.count))
                return fail("expected 'element <name> <count>'");
            e.name = w[1];
            h.elements.push_back(e);
        } else if (w[0] == "property") {
            if (h.elements.empty())
                return fail("property before any element");
            Element& e = h.elements.back();
            if (w.size() >= 2 && w[1] == "list") {
                if (w.size() != 5 || typeSize(std::string(w[2])) == 0 || typeSize(std::string(w[3])) == 0)
                    return fail("expected 'property list <count type> <item type> <name>'");
                if (isFloatType(std::string(w[2])))
                    return fail("the length of list '" + std::string(w[4]) +
                                "' has the floating-point type '" + std::string(w[2]) + "'");
                e.minBinary += typeSize(std::string(w[2]));
                e.props.push_back({std::string(w[4]), std::string(w[3]), std::string(w[2])});
            } else {
                if (w.size() != 3 || typeSize(std::string(w[1])) == 0)
                    return fail("expected 'property <type> <name>'");
                e.minBinary += typeSize(std::string(w[1]));
                e.props.push_back({std::string(w[2]), std::string(w[1]), ""});
            }
        } else {
            return fail("unknown header keyword '" + std::string(w[0]) + "'");
        }
    }
    if (!ended && pos < b.size())
        return parseError(name, "PLY header is longer than the limit of " + std::to_string(kMaxHeader) +
                                    " bytes (no 'end_header' line in them)");
    if (!ended)
        return parseError(name, "PLY header has no 'end_header' line");
    if (!formatSeen)
        return parseError(name, "PLY header has no 'format' line");
    const long double body = pos >= b.size() ? 0.0L : static_cast<long double>(b.size() - pos);
    long double total = 0;
    for (const Element& e : h.elements) {
        const long double per =
            h.format == Header::Format::Ascii
                ? std::max<long double>(1, 2.0L * static_cast<long double>(e.props.size()))
                : std::max<long double>(1, e.minBinary);
        total += per * static_cast<long double>(e.count);
        if (total > body + 1)
            return makeError(ErrorCode::ParseError, name + ":" + std::to_string(e.line) + ": header claims " +
                                                        std::to_string(e.count) + " '" + e.name +
                                                        "' elements (at least " + bytesText(total) +
                                                        " bytes of data) but only " + bytesText(body) +
                                                        " bytes follow the header");
    }
    h.bodyPos = std::min(pos, b.size());
    h.bodyLine = line;
    return h;
}

// The values of an ASCII body: one element per line, errors at file:line.
class AsciiBody {
public:
    AsciiBody(const std::string& b, const std::string& name, const Header& h)
        : b_(b), br_(detail::lineBreakOf(std::string_view(b).substr(0, 64))), name_(name), pos_(h.bodyPos),
          line_(h.bodyLine) {}

    Error fail(const std::string& message) const {
        return makeError(ErrorCode::ParseError, name_ + ":" + std::to_string(line_) + ": " + message);
    }
    bool beginElement() {
        nextLine();
        next_ = 0;
        return !tok_.empty();
    }
    // Empty when a value was read into v; else the problem.
    std::string value(const std::string& /*type*/, const std::string& what, const std::string& prop,
                      double& v) {
        if (next_ >= tok_.size())
            return what + ": the line ends before its properties do (" + std::to_string(tok_.size()) +
                   " numbers; truncated?)";
        const std::string_view t = tok_[next_++];
        switch (detail::parseDouble(t, v)) {
        case detail::NumberStatus::Ok:
            return {};
        case detail::NumberStatus::NotANumber:
            return what + ": expected a number for '" + prop + "', got " + detail::quoted(t);
        case detail::NumberStatus::OutOfRange:
            break;
        }
        return what + ": value " + detail::quoted(t) + " for '" + prop + "' is out of range";
    }
    std::string endElement(const std::string& what) const {
        if (next_ != tok_.size())
            return what + ": " + std::to_string(tok_.size() - next_) +
                   " more numbers than its properties need";
        return {};
    }
    std::string trailing() {
        nextLine();
        if (!tok_.empty())
            return "unexpected " + detail::quoted(tok_[0]) +
                   " after the declared elements (the header's counts do not match the file)";
        return {};
    }

private:
    void nextLine() {
        tok_.clear();
        while (tok_.empty() && pos_ < b_.size()) {
            ++line_;
            std::size_t end = b_.find(br_, pos_);
            if (end == std::string::npos)
                end = b_.size();
            tok_ = detail::tokenize(std::string_view(b_.data() + pos_, end - pos_));
            pos_ = end + 1;
        }
    }

    const std::string& b_;
    char br_; // what ends a line
    const std::string& name_;
    std::size_t pos_, line_;
    std::vector<std::string_view> tok_;
    std::size_t next_ = 0;
};

// The values of a binary body, in either byte order; errors at file: byte offset.
class BinaryBody {
public:
    BinaryBody(const std::string& b, const std::string& name, const Header& h)
        : b_(b), name_(name), pos_(h.bodyPos), big_(h.format == Header::Format::Big) {}

    Error fail(const std::string& message) const {
        return makeError(ErrorCode::ParseError, name_ + ": byte " + std::to_string(at_) + ": " + message);
    }
    bool beginElement() {
        at_ = pos_;
        return pos_ < b_.size();
    }
    std::string value(const std::string& type, const std::string& what, const std::string& prop, double& v) {
        const auto n = static_cast<std::size_t>(typeSize(type));
        if (b_.size() - pos_ < n)
            return what + ": the file ends inside '" + prop + "' (truncated?)";
        std::uint64_t u = 0;
        for (std::size_t i = 0; i < n; ++i) {
            const auto byte = static_cast<unsigned char>(b_[pos_ + (big_ ? i : n - 1 - i)]);
            u = u << 8 | byte;
        }
        pos_ += n;
        if (type == "float" || type == "float32") {
            v = std::bit_cast<float>(static_cast<std::uint32_t>(u));
        } else if (type == "double" || type == "float64") {
            v = std::bit_cast<double>(u);
        } else if (isSignedType(type)) {
            const int bits = static_cast<int>(8 * n);
            const std::uint64_t sign = std::uint64_t{1} << (bits - 1);
            v = static_cast<double>(static_cast<std::int64_t>((u ^ sign) - sign));
        } else {
            v = static_cast<double>(u);
        }
        return {};
    }
    std::string endElement(const std::string&) const { return {}; }
    // Blank bytes (a final newline some exporters add) may follow the elements; anything else may not.
    std::string trailing() {
        at_ = pos_;
        const std::size_t extra = b_.size() - pos_;
        for (std::size_t i = pos_; i < b_.size(); ++i)
            if (!std::isspace(static_cast<unsigned char>(b_[i])) && b_[i] != '\0')
                return std::to_string(extra) +
                       " bytes after the declared elements (the header's counts do not match the file)";
        return {};
    }

private:
    const std::string& b_;
    const std::string& name_;
    std::size_t pos_, at_ = 0;
    bool big_;
};

template <class Body>
Result<Mesh> readBody(Body& body, const Header& h, const std::string& name) {
    std::vector<Vec3> positions;
    std::vector<Triangle> triangles;
    std::size_t vertexCount = 0;
    for (const Element& e : h.elements) {
        const bool isVertex = e.name == "vertex", isFace = e.name == "face";
        int xyz[3] = {-1, -1, -1};
        if (isVertex) {
            for (std::size_t k = 0; k < e.props.size(); ++k)
                for (int c = 0; c < 3; ++c)
                    if (!e.props[k].list() && e.props[k].name == std::string(1, static_cast<char>('x' + c)))
                        xyz[c] = static_cast<int>(k);
            if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)
                return makeError(ErrorCode::ParseError,
                                 name + ":" + std::to_string(e.line) +
                                     ": the vertex element has no x, y and z properties");
            vertexCount = static_cast<std::size_t>(e.count);
        }
        for (std::uint64_t i = 0; i < e.count; ++i) {
            if (!body.beginElement())
                return body.fail("the file ends after " + std::to_string(i) + " of the " +
                                 std::to_string(e.count) + " declared '" + e.name + "' elements");
            const std::string what = "'" + e.name + "' " + std::to_string(i);
            double c[3] = {0, 0, 0};
            std::vector<std::uint32_t> corners;
            for (std::size_t k = 0; k < e.props.size(); ++k) {
                const Property& p = e.props[k];
                double length = 1;
                if (p.list()) {
                    if (std::string why = body.value(p.countType, what, p.name, length); !why.empty())
                        return body.fail(why);
                    if (!(length >= 0 && length == std::floor(length) && length < 4294967296.0))
                        return body.fail(what + ": the length of the list '" + p.name + "' is not a count");
                }
                const bool indices =
                    isFace && p.list() && (p.name == "vertex_indices" || p.name == "vertex_index");
                for (std::uint64_t m = 0; m < static_cast<std::uint64_t>(length); ++m) {
                    double v = 0;
                    if (std::string why = body.value(p.type, what, p.name, v); !why.empty())
                        return body.fail(why);
                    for (int a = 0; a < 3; ++a)
                        if (isVertex && static_cast<int>(k) == xyz[a])
                            c[a] = v;
                    if (indices) {
                        if (!(v >= 0 && v < static_cast<double>(vertexCount)) || v != std::floor(v)) {
                            char shown[32];
                            std::snprintf(shown, sizeof shown, "%.17g", v);
                            return body.fail(what + " refers to vertex " + shown + " but there are " +
                                             std::to_string(vertexCount) + " (PLY indices start at 0)");
                        }
                        corners.push_back(static_cast<std::uint32_t>(v));
                    }
                }
                if (indices && corners.size() < 3)
                    return body.fail(what + " has " + std::to_string(corners.size()) +
                                     (corners.size() == 1 ? " corner" : " corners") +
                                     "; at least 3 are needed");
            }
            if (std::string why = body.endElement(what); !why.empty())
                return body.fail(why);
            if (isVertex)
                positions.push_back({c[0], c[1], c[2]});
            if (corners.size() == 3) {
                triangles.push_back({corners[0], corners[1], corners[2]});
            } else if (!corners.empty()) {
                std::vector<Vec3> pts;
                for (std::uint32_t v : corners)
                    pts.push_back(positions[v]);
                for (const auto& tri : triangulatePolygon(pts))
                    triangles.push_back({corners[tri[0]], corners[tri[1]], corners[tri[2]]});
            }
        }
    }
    if (std::string why = body.trailing(); !why.empty())
        return body.fail(why);
    if (triangles.empty())
        return parseError(name, "no triangles");
    // Unreferenced vertices are dropped.
    Mesh m;
    detail::PositionWelder weld(m);
    std::vector<std::uint32_t> remap(positions.size(), UINT32_MAX);
    for (Triangle& tri : triangles) {
        for (std::uint32_t& v : tri) {
            if (remap[v] == UINT32_MAX)
                remap[v] = weld.add(positions[v]);
            v = remap[v];
        }
        m.triangles.push_back(tri);
    }
    return m;
}
} // namespace

Result<Mesh> parsePly(const std::string& bytes, const std::string& displayName) {
    Result<Header> header = parseHeader(bytes, displayName);
    if (!header)
        return header.error();
    if (header->format == Header::Format::Ascii) {
        AsciiBody body(bytes, displayName, *header);
        return readBody(body, *header, displayName);
    }
    BinaryBody body(bytes, displayName, *header);
    return readBody(body, *header, displayName);
}

} // namespace rubble::io
