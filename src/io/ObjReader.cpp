// Rubble's own OBJ reader: strict about what it cannot interpret, tolerant of what it can ignore.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <unordered_map>

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
using detail::trim;
constexpr std::uint32_t kNoMaterial = 0xFFFF'FFFFu;
constexpr std::uint32_t kUnmapped = 0xFFFF'FFFFu;

struct Corner {
    std::int64_t v = -1, vt = -1, vn = -1; // 0-based, -1 = absent
};

struct Tri {
    std::array<Corner, 3> c;
    std::uint32_t material = kNoMaterial;
    std::uint32_t oSlot = 0, gSlot = 0;
};

bool parseInt(std::string_view s, std::int64_t& out) {
    if (!s.empty() && s.front() == '+')
        s.remove_prefix(1);
    if (s.empty() || s.front() == '+')
        return false;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && ptr == s.data() + s.size();
}

class ObjParser {
public:
    ObjParser(std::string_view text, const std::string& name)
        : text_(text), br_(detail::lineBreakOf(text)), name_(name) {}

    Status parse() {
        std::size_t pos = 0;
        if (text_.substr(0, 3) == "\xEF\xBB\xBF") // UTF-8 byte order mark
            pos = 3;
        while (pos < text_.size()) {
            ++line_;
            std::size_t end = text_.find(br_, pos);
            if (end == std::string_view::npos)
                end = text_.size();
            std::string_view ln = text_.substr(pos, end - pos);
            pos = end + 1;
            if (const int u = detail::binaryByte(ln); u >= 0) {
                char hex[8];
                std::snprintf(hex, sizeof hex, "0x%02X", u);
                return fail(std::string("unexpected binary data (byte ") + hex +
                            "); this is not an OBJ text file");
            }
            if (const std::size_t hash = ln.find('#'); hash != std::string_view::npos)
                ln = ln.substr(0, hash);
            if (Status s = parseLine(ln); !s)
                return s;
        }
        return {};
    }

    Result<std::vector<NamedMesh>> objects() {
        if (tris_.empty()) {
            const std::string why =
                text_.empty() ? "the file is empty"
                : positions_.empty()
                    ? "the file has no vertices or faces"
                    : "the file has " + std::to_string(positions_.size()) + " vertices but no faces";
            return makeError(ErrorCode::ParseError, name_ + ": no triangles (" + why + ")");
        }
        const bool byO = sawO_;
        std::vector<std::vector<std::size_t>> slots(byO ? oNames_.size() : gNames_.size());
        for (std::size_t t = 0; t < tris_.size(); ++t)
            slots[byO ? tris_[t].oSlot : tris_[t].gSlot].push_back(t);
        finishMaterials();
        std::vector<NamedMesh> out;
        for (std::size_t s = 0; s < slots.size(); ++s)
            if (!slots[s].empty())
                out.push_back({byO ? oNames_[s] : gNames_[s], build(slots[s])});
        return out;
    }

    Result<Mesh> merged() {
        if (tris_.empty()) {
            auto r = objects();
            return r.error();
        }
        finishMaterials();
        std::vector<std::size_t> all(tris_.size());
        for (std::size_t t = 0; t < all.size(); ++t)
            all[t] = t;
        return build(all);
    }

private:
    Status fail(const std::string& message) const {
        return makeError(ErrorCode::ParseError, name_ + ":" + std::to_string(line_) + ": " + message);
    }

    Status parseNumbers(const std::vector<std::string_view>& tok, std::size_t needed, std::size_t maxUsed,
                        const char* what, const char* const* names, double* out, bool inFloat = false) {
        if (tok.size() - 1 < needed)
            return fail(std::string(what) + " needs " + std::to_string(needed) +
                        (needed == 1 ? " number" : " numbers") + ", got " + std::to_string(tok.size() - 1));
        for (std::size_t i = 1; i < tok.size(); ++i) {
            double v = 0;
            const std::string field = i - 1 < maxUsed ? names[i - 1] : "value " + std::to_string(i);
            switch (parseDouble(tok[i], v)) {
            case NumberStatus::NotANumber:
                return fail(std::string(what) + ": expected a number for " + field + ", got " +
                            quoted(tok[i]));
            case NumberStatus::OutOfRange:
                return fail(std::string(what) + ": value " + quoted(tok[i]) + " for " + field +
                            " is out of range");
            case NumberStatus::Ok:
                break;
            }
            if (inFloat && !(std::abs(v) <= std::numeric_limits<float>::max())) // attributes are float
                return fail(std::string(what) + ": value " + quoted(tok[i]) + " for " + field +
                            " is beyond float's range");
            if (i - 1 < maxUsed)
                out[i - 1] = v;
        }
        return {};
    }

    Status parseLine(std::string_view ln) {
        const std::vector<std::string_view> tok = tokenize(ln);
        if (tok.empty())
            return {};
        const std::string_view key = tok[0];
        if (key == "v") {
            static const char* const names[] = {"x", "y", "z"};
            double c[3] = {0, 0, 0};
            if (Status s = parseNumbers(tok, 3, 3, "vertex", names, c); !s)
                return s;
            if (positions_.size() >= 0xFFFF'FFF0u)
                return fail("too many vertices");
            positions_.push_back({c[0], c[1], c[2]});
        } else if (key == "vt") {
            static const char* const names[] = {"u", "v", "w"};
            double c[3] = {0, 0, 0};
            if (Status s = parseNumbers(tok, 1, 3, "texture coordinate", names, c, true); !s)
                return s;
            texcoords_.emplace_back(c[0], c[1]);
        } else if (key == "vn") {
            static const char* const names[] = {"x", "y", "z"};
            double c[3] = {0, 0, 0};
            if (Status s = parseNumbers(tok, 3, 3, "normal", names, c, true); !s)
                return s;
            normals_.emplace_back(c[0], c[1], c[2]);
        } else if (key == "f" || key == "fo") {
            return parseFace(tok);
        } else if (key == "o") {
            sawO_ = true;
            oNames_.emplace_back(trim(ln.substr(ln.find('o') + 1)));
            curO_ = static_cast<std::uint32_t>(oNames_.size() - 1);
        } else if (key == "g") {
            gNames_.emplace_back(trim(ln.substr(ln.find('g') + 1)));
            curG_ = static_cast<std::uint32_t>(gNames_.size() - 1);
        } else if (key == "usemtl") {
            const std::string name(trim(ln.substr(ln.find("usemtl") + 6)));
            if (name == kInteriorMaterialName) {
                curMat_ = kInteriorMaterial;
            } else {
                auto [it, inserted] =
                    materialIds_.emplace(name, static_cast<std::uint32_t>(materialNames_.size()));
                if (inserted)
                    materialNames_.push_back(name);
                curMat_ = it->second;
            }
        }
        // Everything else (s, mtllib, l, p, vp, curves, ...) does not affect the triangles: ignored.
        return {};
    }

    Status resolve(std::string_view tokenText, std::string_view part, std::size_t count, const char* what,
                   std::int64_t& out) {
        std::int64_t k = 0;
        if (!parseInt(part, k))
            return fail("face corner " + quoted(tokenText) + ": expected a " + what + " index, got " +
                        quoted(part));
        if (k == 0)
            return fail(std::string("face refers to ") + what + " 0, but OBJ indices start at 1");
        const auto n = static_cast<std::int64_t>(count);
        const std::int64_t idx = k > 0 ? k - 1 : n + k;
        if (idx < 0 || idx >= n)
            return fail(std::string("face refers to ") + what + " " + std::to_string(k) +
                        " (OBJ counts from 1) but only " + std::to_string(count) +
                        (count == 1 ? " is" : " are") + " defined");
        out = idx;
        return {};
    }

    Status parseFace(const std::vector<std::string_view>& tok) {
        std::vector<Corner> poly;
        poly.reserve(tok.size() - 1);
        for (std::size_t i = 1; i < tok.size(); ++i) {
            const std::string_view t = tok[i];
            std::string_view parts[3];
            std::size_t np = 0, start = 0;
            for (std::size_t j = 0; j <= t.size(); ++j)
                if (j == t.size() || t[j] == '/') {
                    if (np == 3)
                        return fail("face corner " + quoted(t) + ": expected v, v/vt, v//vn or v/vt/vn");
                    parts[np++] = t.substr(start, j - start);
                    start = j + 1;
                }
            Corner c;
            if (Status s = resolve(t, parts[0], positions_.size(), "vertex", c.v); !s)
                return s;
            if (np >= 2 && !parts[1].empty())
                if (Status s = resolve(t, parts[1], texcoords_.size(), "texture coordinate", c.vt); !s)
                    return s;
            if (np == 3 && !parts[2].empty())
                if (Status s = resolve(t, parts[2], normals_.size(), "normal", c.vn); !s)
                    return s;
            poly.push_back(c);
        }
        if (poly.size() < 3) {
            return fail("face has " + std::to_string(poly.size()) +
                        (poly.size() == 1 ? " corner" : " corners") + "; at least 3 are needed");
        }
        Tri base;
        base.material = curMat_;
        base.oSlot = curO_;
        base.gSlot = curG_;
        if (poly.size() == 3) {
            base.c = {poly[0], poly[1], poly[2]};
            tris_.push_back(base);
            return {};
        }
        std::vector<Vec3> pts(poly.size());
        for (std::size_t i = 0; i < poly.size(); ++i)
            pts[i] = positions_[static_cast<std::size_t>(poly[i].v)];
        for (const auto& t : io::triangulatePolygon(pts)) {
            base.c = {poly[t[0]], poly[t[1]], poly[t[2]]};
            tris_.push_back(base);
        }
        return {};
    }

    void finishMaterials() {
        if (materialsFinished_)
            return;
        materialsFinished_ = true;
        bool any = false, missing = false;
        for (const Tri& t : tris_) {
            any = any || t.material != kNoMaterial;
            missing = missing || t.material == kNoMaterial;
        }
        hasMaterials_ = any;
        if (any && missing) {
            auto [it, inserted] =
                materialIds_.emplace("default", static_cast<std::uint32_t>(materialNames_.size()));
            if (inserted)
                materialNames_.push_back("default");
            for (Tri& t : tris_)
                if (t.material == kNoMaterial)
                    t.material = it->second;
        }
    }

    Mesh build(const std::vector<std::size_t>& which) {
        Mesh m;
        bool anyNormal = false, anyUv = false;
        for (std::size_t t : which)
            for (const Corner& c : tris_[t].c) {
                anyNormal = anyNormal || c.vn >= 0;
                anyUv = anyUv || c.vt >= 0;
            }
        if (remap_.size() != positions_.size())
            remap_.assign(positions_.size(), kUnmapped);
        // Vertices keep their order in the file (ascending global index).
        std::vector<std::uint32_t> touched;
        for (std::size_t t : which)
            for (const Corner& c : tris_[t].c) {
                const auto v = static_cast<std::size_t>(c.v);
                if (remap_[v] == kUnmapped) {
                    remap_[v] = 0;
                    touched.push_back(static_cast<std::uint32_t>(v));
                }
            }
        std::sort(touched.begin(), touched.end());
        m.positions.reserve(touched.size());
        for (std::uint32_t v : touched) {
            remap_[v] = static_cast<std::uint32_t>(m.positions.size());
            m.positions.push_back(positions_[v]);
        }
        for (std::size_t t : which) {
            const Tri& tri = tris_[t];
            Triangle out;
            for (int k = 0; k < 3; ++k)
                out[k] = remap_[static_cast<std::size_t>(tri.c[k].v)];
            m.triangles.push_back(out);
            if (anyNormal) {
                const Vec3f flat(normalized(m.triangleNormal(m.triangles.size() - 1)));
                for (const Corner& c : tri.c)
                    m.normals.push_back(c.vn >= 0 ? normals_[static_cast<std::size_t>(c.vn)] : flat);
            }
            if (anyUv)
                for (const Corner& c : tri.c)
                    m.uvs.push_back(c.vt >= 0 ? texcoords_[static_cast<std::size_t>(c.vt)] : Vec2f{});
            if (hasMaterials_)
                m.materials.push_back(tri.material);
        }
        for (std::uint32_t v : touched)
            remap_[v] = kUnmapped;
        if (hasMaterials_)
            m.materialNames = materialNames_;
        return m;
    }

    std::string_view text_;
    char br_; // what ends a line
    std::string name_;
    std::size_t line_ = 0;
    std::vector<Vec3> positions_;
    std::vector<Vec2f> texcoords_;
    std::vector<Vec3f> normals_;
    std::vector<Tri> tris_;
    std::vector<std::string> oNames_{""}, gNames_{""};
    bool sawO_ = false;
    std::uint32_t curO_ = 0, curG_ = 0;
    std::vector<std::string> materialNames_;
    std::unordered_map<std::string, std::uint32_t> materialIds_;
    std::uint32_t curMat_ = kNoMaterial;
    bool materialsFinished_ = false, hasMaterials_ = false;
    std::vector<std::uint32_t> remap_;
};
} // namespace

Result<std::vector<NamedMesh>> parseObjObjects(std::string_view text, const std::string& displayName) {
    ObjParser parser(text, displayName);
    if (Status s = parser.parse(); !s)
        return s.error();
    return parser.objects();
}

Result<Mesh> parseObj(std::string_view text, const std::string& displayName) {
    ObjParser parser(text, displayName);
    if (Status s = parser.parse(); !s)
        return s.error();
    return parser.merged();
}

Result<Mesh> readObj(const std::filesystem::path& path) {
    auto bytes = io::readFileBytes(path);
    if (!bytes)
        return bytes.error();
    return parseObj(bytes.value(), io::displayName(path));
}

Result<std::vector<NamedMesh>> readObjObjects(const std::filesystem::path& path) {
    auto bytes = io::readFileBytes(path);
    if (!bytes)
        return bytes.error();
    return parseObjObjects(bytes.value(), io::displayName(path));
}

} // namespace rubble
