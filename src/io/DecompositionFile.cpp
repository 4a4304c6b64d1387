#include "rubble/io/DecompositionFile.hpp"

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "io/FileBytes.hpp"

namespace rubble {

namespace {

using nlohmann::json;

std::string hex(std::uint64_t v) {
    char buf[20];
    std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
    return buf;
}

json vec(const Vec3& v) {
    return json::array({v.x, v.y, v.z});
}

/// Reading with errors that name the file and the field ("parts[2].faces[0].normal").
class FieldReader {
public:
    explicit FieldReader(std::string file) : file_(std::move(file)) {}
    Error fail(const std::string& field, const std::string& what) const {
        return {ErrorCode::ParseError, file_ + ": " + field + ": " + what};
    }
    bool number(const json& j, const std::string& field, double& out, Error& err) const {
        if (!j.is_number()) {
            err = fail(field, "expected a number");
            return false;
        }
        out = j.get<double>();
        if (!std::isfinite(out)) {
            err = fail(field, "not finite");
            return false;
        }
        return true;
    }
    bool point(const json& j, const std::string& field, Vec3& out, Error& err) const {
        if (!j.is_array() || j.size() != 3) {
            err = fail(field, "expected [x, y, z]");
            return false;
        }
        for (std::size_t a = 0; a < 3; ++a)
            if (!number(j[a], field + "[" + std::to_string(a) + "]", out[static_cast<int>(a)], err))
                return false;
        return true;
    }

private:
    std::string file_;
};

} // namespace

std::filesystem::path decompositionPathFor(const std::filesystem::path& meshPath) {
    std::filesystem::path p = meshPath;
    p.replace_extension(".parts.json");
    return p;
}

Status writeDecompositionFile(const std::filesystem::path& path, const DecompositionFile& file) {
    json j;
    j["format"] = "rubble-decomposition";
    j["version"] = 2;
    j["mesh_hash"] = hex(file.meshHash);
    j["mesh_volume"] = file.meshVolume;
    json parts = json::array();
    for (const ConvexPolytope& part : file.parts) {
        json faces = json::array();
        for (const PolytopeFaceView& f : part.faces()) {
            json corners = json::array();
            for (const Vec3& c : f.corners)
                corners.push_back(vec(c));
            faces.push_back(
                {{"normal", vec(f.plane.normal)}, {"offset", f.plane.offset}, {"corners", corners}});
        }
        parts.push_back({{"faces", std::move(faces)}});
    }
    j["parts"] = std::move(parts);
    return io::writeFileAtomically(path, j.dump() + "\n");
}

Result<DecompositionFile> readDecompositionFile(const std::filesystem::path& path) {
    auto bytes = io::readFileBytes(path);
    if (!bytes)
        return bytes.error();
    const std::string name = io::displayName(path);
    json j;
    try {
        j = json::parse(*bytes);
    } catch (const json::parse_error& e) {
        return makeError(ErrorCode::ParseError,
                         name + ": byte " + std::to_string(e.byte) + ": not JSON (" + e.what() + ")");
    }
    const FieldReader r(name);
    if (!j.is_object())
        return r.fail("(top level)", "expected an object");
    if (!j.contains("format") || j["format"] != "rubble-decomposition")
        return r.fail("format", "expected \"rubble-decomposition\"");
    if (!j.contains("version") || !(j["version"] == 1 || j["version"] == 2))
        return r.fail("version", "expected 1 or 2");
    DecompositionFile out;
    Error err;
    if (!j.contains("mesh_hash") || !j["mesh_hash"].is_string())
        return r.fail("mesh_hash", "expected 16 hex digits");
    {
        const std::string h = j["mesh_hash"].get<std::string>();
        if (h.size() != 16 || h.find_first_not_of("0123456789abcdef") != std::string::npos)
            return r.fail("mesh_hash", "expected 16 lower-case hex digits");
        out.meshHash = std::stoull(h, nullptr, 16);
    }
    if (!j.contains("mesh_volume") || !r.number(j["mesh_volume"], "mesh_volume", out.meshVolume, err))
        return j.contains("mesh_volume") ? err : r.fail("mesh_volume", "missing");
    if (!j.contains("parts") || !j["parts"].is_array())
        return r.fail("parts", "expected an array");
    for (std::size_t p = 0; p < j["parts"].size(); ++p) {
        const json& part = j["parts"][p];
        const std::string where = "parts[" + std::to_string(p) + "]";
        if (!part.is_object() || !part.contains("faces") || !part["faces"].is_array())
            return r.fail(where + ".faces", "expected an array");
        std::vector<PolytopeFace> faces;
        for (std::size_t f = 0; f < part["faces"].size(); ++f) {
            const json& face = part["faces"][f];
            const std::string at = where + ".faces[" + std::to_string(f) + "]";
            if (!face.is_object())
                return r.fail(at, "expected an object");
            PolytopeFace pf;
            if (!face.contains("normal") || !r.point(face["normal"], at + ".normal", pf.plane.normal, err))
                return face.contains("normal") ? err : r.fail(at + ".normal", "missing");
            if (!face.contains("offset") || !r.number(face["offset"], at + ".offset", pf.plane.offset, err))
                return face.contains("offset") ? err : r.fail(at + ".offset", "missing");
            if (!face.contains("corners") || !face["corners"].is_array() || face["corners"].size() < 3)
                return r.fail(at + ".corners", "expected an array of at least 3 points");
            for (std::size_t c = 0; c < face["corners"].size(); ++c) {
                Vec3 v;
                if (!r.point(face["corners"][c], at + ".corners[" + std::to_string(c) + "]", v, err))
                    return err;
                pf.corners.push_back(v);
            }
            faces.push_back(std::move(pf));
        }
        ConvexPolytope poly = ConvexPolytope::fromFaces(std::move(faces));
        if (poly.empty() || !(poly.volume() > 0))
            return r.fail(where, "not a solid (fewer than 4 faces or no volume)");
        out.parts.push_back(std::move(poly));
    }
    return out;
}

} // namespace rubble
