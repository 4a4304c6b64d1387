// Rubble's own OFF reader: exact numbers, polygons of any size, comments anywhere, declared counts checked.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "io/FileBytes.hpp"
#include "io/PolygonTriangulation.hpp"
#include "io/TextTokens.hpp"
#include "rubble/io/MeshIO.hpp"

namespace rubble {

namespace {

using detail::isSpace;
using detail::NumberStatus;
using detail::parseDouble;
using detail::quoted;
using detail::tokenize;
bool parseCount(std::string_view s, std::uint64_t& out) {
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && ptr == s.data() + s.size();
}

class OffParser {
public:
    OffParser(std::string_view text, const std::string& name)
        : text_(text), br_(detail::lineBreakOf(text)), name_(name) {}

    Result<Mesh> parse() {
        if (text_.substr(0, 3) == "\xEF\xBB\xBF") // UTF-8 byte order mark
            pos_ = 3;
        std::vector<std::string_view> tok;
        if (Status s = nextLine(tok); !s)
            return s.error();
        if (tok.empty())
            return makeError(ErrorCode::ParseError, name_ + ": no triangles (the file is empty)");
        if (Status s = header(tok); !s)
            return s.error();
        for (std::uint64_t v = 0; v < nv_; ++v) {
            if (Status s = nextLine(tok); !s)
                return s.error();
            if (tok.empty())
                return endsEarly("vertices", v, nv_).error();
            if (Status s = vertex(tok); !s)
                return s.error();
        }
        for (std::uint64_t f = 0; f < nf_; ++f) {
            if (Status s = nextLine(tok); !s)
                return s.error();
            if (tok.empty())
                return endsEarly("faces", f, nf_).error();
            if (Status s = face(tok); !s)
                return s.error();
        }
        if (Status s = nextLine(tok); !s)
            return s.error();
        if (!tok.empty())
            return fail("unexpected " + quoted(tok[0]) + " after the " + std::to_string(nf_) +
                        " declared faces (the header's counts do not match the file)")
                .error();
        if (triangles_.empty())
            return makeError(ErrorCode::ParseError, name_ + ": no triangles (the file has " +
                                                        std::to_string(nv_) + " vertices but no faces)");
        return build();
    }

private:
    Status fail(const std::string& message) const {
        return makeError(ErrorCode::ParseError, name_ + ":" + std::to_string(line_) + ": " + message);
    }

    Status endsEarly(const char* what, std::uint64_t got, std::uint64_t declared) const {
        return fail("the file ends after " + std::to_string(got) + " of the " + std::to_string(declared) +
                    " declared " + what);
    }

    // The tokens of the next line that has any (comments removed); empty at the end of the file.
    Status nextLine(std::vector<std::string_view>& tok) {
        tok.clear();
        while (tok.empty() && pos_ < text_.size()) {
            ++line_;
            std::size_t end = text_.find(br_, pos_);
            if (end == std::string_view::npos)
                end = text_.size();
            std::string_view ln = text_.substr(pos_, end - pos_);
            pos_ = end + 1;
            if (const int u = detail::binaryByte(ln); u >= 0) {
                char hex[8];
                std::snprintf(hex, sizeof hex, "0x%02X", u);
                return fail(std::string("unexpected binary data (byte ") + hex +
                            "); this is not an OFF text file");
            }
            if (const std::size_t hash = ln.find('#'); hash != std::string_view::npos)
                ln = ln.substr(0, hash);
            tok = tokenize(ln);
        }
        return {};
    }

    // [ST][C][N][4][n]OFF, then (for nOFF) the dimension and the counts, on that line or the next ones.
    Status header(std::vector<std::string_view> tok) {
        std::string_view key = tok[0];
        if (key.size() < 3 || key.substr(key.size() - 3) != "OFF")
            return fail("not an OFF file (it does not start with 'OFF')");
        std::string_view prefix = key.substr(0, key.size() - 3);
        bool homogeneous = false, dimensionGiven = false;
        for (const std::string_view p : {"ST", "C", "N", "4", "n"})
            if (prefix.substr(0, p.size()) == p) {
                homogeneous = homogeneous || p == "4";
                dimensionGiven = dimensionGiven || p == "n";
                prefix.remove_prefix(p.size());
            }
        if (!prefix.empty())
            return fail("unknown OFF variant " + quoted(key));
        tok.erase(tok.begin());
        if (!tok.empty() && tok[0] == "BINARY")
            return makeError(ErrorCode::Unsupported, name_ + ": binary OFF files are not supported");
        const std::size_t needed = dimensionGiven ? 3 : 2;
        std::vector<std::string_view> counts(tok.begin(), tok.end());
        while (counts.size() < needed) {
            if (Status s = nextLine(tok); !s)
                return s;
            if (tok.empty())
                return fail("expected the vertex and face counts after 'OFF'");
            counts.insert(counts.end(), tok.begin(), tok.end());
        }
        if (counts.size() > needed + 1)
            return fail("expected the vertex, face and edge counts after 'OFF', got " +
                        quoted(counts.back()));
        std::uint64_t dim = 3;
        std::size_t k = 0;
        if (dimensionGiven && (!parseCount(counts[k++], dim) || dim != 3))
            return makeError(ErrorCode::Unsupported,
                             name_ + ":" + std::to_string(line_) +
                                 ": only 3-dimensional OFF files are supported (dimension " +
                                 quoted(counts[0]) + ")");
        std::uint64_t ne = 0;
        if (!parseCount(counts[k], nv_) || !parseCount(counts[k + 1], nf_) ||
            (counts.size() > k + 2 && !parseCount(counts[k + 2], ne)))
            return fail("expected the vertex, face and edge counts after 'OFF', got " + quoted(counts[k]) +
                        " " + quoted(counts[k + 1]));
        if (nv_ > 0xFFFF'FFF0u)
            return fail("too many vertices (" + std::to_string(nv_) + ")");
        coordinates_ = homogeneous ? 4 : 3;
        return {};
    }

    // x y z (x y z w for 4OFF); what follows (normal, colour, texture coordinates) is ignored.
    Status vertex(const std::vector<std::string_view>& tok) {
        static const char* const names[] = {"x", "y", "z", "w"};
        if (tok.size() < coordinates_)
            return fail("vertex " + std::to_string(positions_.size()) + " needs " +
                        std::to_string(coordinates_) + " numbers, got " + std::to_string(tok.size()));
        double c[4] = {0, 0, 0, 1};
        for (std::size_t i = 0; i < coordinates_; ++i)
            switch (parseDouble(tok[i], c[i])) {
            case NumberStatus::NotANumber:
                return fail("vertex " + std::to_string(positions_.size()) + ": expected a number for " +
                            names[i] + ", got " + quoted(tok[i]));
            case NumberStatus::OutOfRange:
                return fail("vertex " + std::to_string(positions_.size()) + ": value " + quoted(tok[i]) +
                            " for " + names[i] + " is out of range");
            case NumberStatus::Ok:
                break;
            }
        if (coordinates_ == 4 && c[3] != 1) {
            if (c[3] == 0)
                return fail("vertex " + std::to_string(positions_.size()) + ": w is 0 (a point at infinity)");
            c[0] /= c[3];
            c[1] /= c[3];
            c[2] /= c[3];
        }
        positions_.push_back({c[0], c[1], c[2]});
        return {};
    }

    // n i1 ... in; what follows (a colour) is ignored.
    Status face(const std::vector<std::string_view>& tok) {
        std::uint64_t n = 0;
        if (!parseCount(tok[0], n))
            return fail("face: expected the number of corners, got " + quoted(tok[0]));
        if (n > tok.size() - 1)
            return fail("face declares " + std::to_string(n) + " corners but lists " +
                        std::to_string(tok.size() - 1) + " numbers");
        if (n < 3)
            return fail("face has " + std::to_string(n) + (n == 1 ? " corner" : " corners") +
                        "; at least 3 are needed");
        std::vector<std::uint32_t> corners(static_cast<std::size_t>(n));
        for (std::size_t i = 0; i < corners.size(); ++i) {
            std::uint64_t v = 0;
            if (!parseCount(tok[i + 1], v))
                return fail("face: expected a vertex index, got " + quoted(tok[i + 1]));
            if (v >= nv_)
                return fail("face refers to vertex " + std::to_string(v) + " but only " +
                            std::to_string(nv_) + (nv_ == 1 ? " is" : " are") +
                            " declared (OFF indices start at 0)");
            corners[i] = static_cast<std::uint32_t>(v);
        }
        if (corners.size() == 3) {
            triangles_.push_back({corners[0], corners[1], corners[2]});
            return {};
        }
        std::vector<Vec3> pts(corners.size());
        for (std::size_t i = 0; i < corners.size(); ++i)
            pts[i] = positions_[corners[i]];
        for (const auto& t : io::triangulatePolygon(pts))
            triangles_.push_back({corners[t[0]], corners[t[1]], corners[t[2]]});
        return {};
    }

    // Unreferenced vertices are dropped; the others keep their order.
    Mesh build() {
        std::vector<std::uint32_t> remap(positions_.size(), UINT32_MAX);
        for (const Triangle& t : triangles_)
            for (std::uint32_t v : t)
                remap[v] = 0;
        Mesh m;
        for (std::size_t v = 0; v < positions_.size(); ++v)
            if (remap[v] == 0) {
                remap[v] = static_cast<std::uint32_t>(m.positions.size());
                m.positions.push_back(positions_[v]);
            }
        m.triangles = std::move(triangles_);
        for (Triangle& t : m.triangles)
            for (std::uint32_t& v : t)
                v = remap[v];
        return m;
    }

    std::string_view text_;
    char br_; // what ends a line
    std::string name_;
    std::size_t pos_ = 0, line_ = 0;
    std::uint64_t nv_ = 0, nf_ = 0;
    std::size_t coordinates_ = 3;
    std::vector<Vec3> positions_;
    std::vector<Triangle> triangles_;
};
} // namespace

Result<Mesh> parseOff(std::string_view text, const std::string& displayName) {
    return OffParser(text, displayName).parse();
}

} // namespace rubble
