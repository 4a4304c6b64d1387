// OBJ + MTL writer with exact (shortest round-trip) numbers.
#include <algorithm>
#include <array>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <unordered_map>

#include "io/FileBytes.hpp"
#include "io/TextureFiles.hpp"
#include "rubble/io/MeshIO.hpp"

namespace rubble {

namespace {
// The shortest text that reads back as v (a float's as a float: attributes).
template <class Real>
void appendNumber(std::string& out, Real v) {
    char buf[64];
    const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v == 0 ? Real(0) : v);
    out.append(buf, ec == std::errc() ? ptr : buf);
}

// A "v x y z" line.
void appendVertex(std::string& out, const Vec3& p) {
    out += "v ";
    appendNumber(out, p.x);
    out += ' ';
    appendNumber(out, p.y);
    out += ' ';
    appendNumber(out, p.z);
    out += '\n';
}

std::string sanitizeName(const std::string& name) {
    std::string s = name;
    for (char& c : s)
        if (static_cast<unsigned char>(c) <= ' ' || c == '#')
            c = '_';
    return s;
}

std::string materialName(const Mesh& m, std::uint32_t id) {
    if (id == kInteriorMaterial)
        return std::string(kInteriorMaterialName);
    if (id < m.materialNames.size() && !m.materialNames[id].empty() &&
        m.materialNames[id] != kInteriorMaterialName)
        return sanitizeName(m.materialNames[id]);
    return "material_" + std::to_string(id);
}

// Deduplicates attribute values (float) by their bit pattern, numbering them from 1 in first-use order.
template <std::size_t N>
class AttributeTable {
public:
    std::size_t id(const std::array<float, N>& v) {
        std::array<std::uint32_t, N> key;
        for (std::size_t i = 0; i < N; ++i) {
            const float f = v[i] == 0 ? 0.0f : v[i];
            std::memcpy(&key[i], &f, sizeof f);
        }
        auto [it, inserted] = ids_.emplace(key, values_.size() + 1);
        if (inserted)
            values_.push_back(v);
        return it->second;
    }
    const std::vector<std::array<float, N>>& values() const { return values_; }

private:
    std::map<std::array<std::uint32_t, N>, std::size_t> ids_;
    std::vector<std::array<float, N>> values_;
};

Status writeText(const std::filesystem::path& path, const std::string& text) {
    return io::writeFileAtomically(path, text);
}
} // namespace

Status writeObj(const std::filesystem::path& path, const Mesh& mesh, const ObjWriteOptions& options) {
    if (Status s = mesh.validate(); !s && s.error().message.find("non-finite") == std::string::npos)
        return makeError(ErrorCode::InvalidInput, io::displayName(path) + ": cannot write: " + s.message());
    if (!options.collision.empty() && options.objectName.empty())
        return makeError(ErrorCode::InvalidInput,
                         io::displayName(path) + ": cannot write collision parts without an object name");
    for (const Mesh& part : options.collision)
        if (Status s = part.validate(); !s || part.empty())
            return makeError(ErrorCode::InvalidInput, io::displayName(path) +
                                                          ": cannot write a collision part: " +
                                                          (s ? std::string("no triangles") : s.message()));
    const bool normals = options.writeNormals && mesh.hasNormals();
    const bool uvs = options.writeUvs && mesh.hasUvs();
    const bool materials = options.writeMaterials && mesh.hasMaterials();
    std::filesystem::path mtlPath = path;
    mtlPath.replace_extension(".mtl");

    std::string out;
    out.reserve(mesh.positions.size() * 40 + mesh.triangles.size() * 30);
    out += "# written by Rubble: " + std::to_string(mesh.positions.size()) + " vertices, " +
           std::to_string(mesh.triangles.size()) + " triangles\n";
    if (materials)
        out += "mtllib " + mtlPath.filename().string() + "\n";
    if (!options.objectName.empty())
        out += "o " + sanitizeName(options.objectName) + "\n";
    for (const Vec3& p : mesh.positions) {
        appendVertex(out, p);
    }
    AttributeTable<2> uvTable;
    AttributeTable<3> normalTable;
    std::vector<std::size_t> uvId, normalId;
    if (uvs) {
        uvId.reserve(mesh.uvs.size());
        for (const Vec2f& t : mesh.uvs)
            uvId.push_back(uvTable.id({t.x, t.y}));
        for (const auto& t : uvTable.values()) {
            out += "vt ";
            appendNumber(out, t[0]);
            out += ' ';
            appendNumber(out, t[1]);
            out += '\n';
        }
    }
    if (normals) {
        normalId.reserve(mesh.normals.size());
        for (const Vec3f& n : mesh.normals)
            normalId.push_back(normalTable.id({n.x, n.y, n.z}));
        for (const auto& n : normalTable.values()) {
            out += "vn ";
            appendNumber(out, n[0]);
            out += ' ';
            appendNumber(out, n[1]);
            out += ' ';
            appendNumber(out, n[2]);
            out += '\n';
        }
    }
    std::map<std::uint32_t, std::string> used; // material id -> name, for the MTL file
    std::uint32_t current = 0;
    bool haveCurrent = false;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (materials && (!haveCurrent || mesh.materials[t] != current)) {
            current = mesh.materials[t];
            haveCurrent = true;
            const std::string name = materialName(mesh, current);
            used.emplace(current, name);
            out += "usemtl " + name + "\n";
        }
        out += 'f';
        for (int c = 0; c < 3; ++c) {
            out += ' ';
            out += std::to_string(std::uint64_t{mesh.triangles[t][c]} + 1);
            if (uvs || normals) {
                out += '/';
                if (uvs)
                    out += std::to_string(uvId[3 * t + c]);
                if (normals)
                    out += '/' + std::to_string(normalId[3 * t + c]);
            }
        }
        out += '\n';
    }
    // Collision parts: UCX_<object>_<nn>, vertices numbered after the mesh's.
    std::uint64_t base = mesh.positions.size();
    for (std::size_t k = 0; k < options.collision.size(); ++k) {
        const Mesh& part = options.collision[k];
        char suffix[32];
        std::snprintf(suffix, sizeof suffix, "_%02zu", k);
        out += "o UCX_" + sanitizeName(options.objectName) + suffix + "\n";
        for (const Vec3& p : part.positions) {
            appendVertex(out, p);
        }
        for (const Triangle& t : part.triangles)
            out += "f " + std::to_string(base + t[0] + 1) + ' ' + std::to_string(base + t[1] + 1) + ' ' +
                   std::to_string(base + t[2] + 1) + '\n';
        base += part.positions.size();
    }
    if (Status s = writeText(path, out); !s)
        return s;
    if (!materials)
        return {};

    // A small palette for ordinary materials; the interior gets its own warm colour.
    static constexpr double palette[][3] = {{0.8, 0.8, 0.8},  {0.55, 0.6, 0.7}, {0.7, 0.65, 0.5},
                                            {0.5, 0.65, 0.5}, {0.65, 0.5, 0.6}, {0.6, 0.6, 0.45}};
    std::string mtl = "# written by Rubble\n";
    std::size_t k = 0;
    io::TextureFiles textures(path.has_parent_path() ? path.parent_path() : std::filesystem::path("."));
    for (const auto& [id, name] : used) {
        const std::string sourceName = id == kInteriorMaterial          ? std::string(kInteriorMaterialName)
                                       : id < mesh.materialNames.size() ? mesh.materialNames[id]
                                                                        : std::string();
        const auto defined = std::find_if(options.materials.begin(), options.materials.end(),
                                          [&](const AssetMaterial& m) { return m.name == sourceName; });
        if (!sourceName.empty() && defined != options.materials.end()) {
            // The source definition: its statements, its colour and its maps with the images copied.
            if (id != kInteriorMaterial)
                ++k;
            mtl += "\nnewmtl " + name + "\n";
            for (const std::string& statement : defined->statements)
                if (statement.rfind("Kd", 0) != 0)
                    mtl += statement + "\n";
            mtl += "Kd ";
            appendNumber(mtl, defined->baseColor.x);
            mtl += ' ';
            appendNumber(mtl, defined->baseColor.y);
            mtl += ' ';
            appendNumber(mtl, defined->baseColor.z);
            mtl += '\n';
            for (const TextureMap& map : defined->maps) {
                auto uri = textures.place(map);
                if (!uri)
                    return uri.error();
                mtl += map.slot + ' ' + (map.options.empty() ? "" : map.options + ' ') + uri.value() + '\n';
            }
            continue;
        }
        const double* kd = id == kInteriorMaterial ? nullptr : palette[k++ % std::size(palette)];
        const double interior[3] = {0.85, 0.45, 0.2};
        if (!kd)
            kd = interior;
        mtl += "\nnewmtl " + name + "\nKa 0.2 0.2 0.2\nKd ";
        appendNumber(mtl, kd[0]);
        mtl += ' ';
        appendNumber(mtl, kd[1]);
        mtl += ' ';
        appendNumber(mtl, kd[2]);
        mtl += "\nKs 0 0 0\nd 1\nillum 1\n";
    }
    return writeText(mtlPath, mtl);
}

} // namespace rubble
