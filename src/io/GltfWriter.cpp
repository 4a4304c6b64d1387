// glTF 2.0 writer: one node per mesh with its collision children, a material per material name, one embedded
// base64 buffer, texture images copied next to the file.
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "io/FileBytes.hpp"
#include "io/TextureFiles.hpp"
#include "rubble/io/MeshIO.hpp"

namespace rubble {

namespace {

constexpr int kFloat = 5126;
constexpr int kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;

std::string base64(const std::string& bytes) {
    static constexpr char table[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const std::uint32_t v = std::uint32_t{static_cast<unsigned char>(bytes[i])} << 16 |
                                std::uint32_t{static_cast<unsigned char>(bytes[i + 1])} << 8 |
                                std::uint32_t{static_cast<unsigned char>(bytes[i + 2])};
        for (int s = 18; s >= 0; s -= 6)
            out += table[(v >> s) & 63];
    }
    if (const std::size_t rest = bytes.size() - i; rest > 0) {
        std::uint32_t v = std::uint32_t{static_cast<unsigned char>(bytes[i])} << 16;
        if (rest == 2)
            v |= std::uint32_t{static_cast<unsigned char>(bytes[i + 1])} << 8;
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += rest == 2 ? table[(v >> 6) & 63] : '=';
        out += '=';
    }
    return out;
}

template <class T>
void appendRaw(std::string& buffer, const T& value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    buffer.append(raw, sizeof(T));
}

// The vertices and indices of one primitive (the triangles of one material).
struct Primitive {
    std::vector<std::array<float, 8>> vertices; // position (relative to origin), normal, uv
    std::vector<std::uint32_t> indices;
};

Primitive buildPrimitive(const Mesh& mesh, const Vec3& origin, std::uint32_t material) {
    Primitive prim;
    std::map<std::array<std::uint32_t, 8>, std::uint32_t> ids; // by bit pattern
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (mesh.material(t) != material)
            continue;
        const Vec3 flat = normalized(mesh.triangleNormal(t));
        for (int c = 0; c < 3; ++c) {
            const std::size_t k = 3 * t + static_cast<std::size_t>(c);
            const Vec3 p = mesh.positions[mesh.triangles[t][static_cast<std::size_t>(c)]] - origin;
            Vec3 n = mesh.hasNormals() ? mesh.normals[k] : flat;
            n = lengthSquared(n) > 0 ? normalized(n) : flat;
            if (!isFinite(n))
                n = Vec3{0, 0, 1};
            const Vec2 uv = mesh.hasUvs() ? mesh.uvs[k] : Vec2{0, 0};
            const std::array<float, 8> v = {static_cast<float>(p.x),  static_cast<float>(p.y),
                                            static_cast<float>(p.z),  static_cast<float>(n.x),
                                            static_cast<float>(n.y),  static_cast<float>(n.z),
                                            static_cast<float>(uv.x), static_cast<float>(1.0 - uv.y)};
            std::array<std::uint32_t, 8> key;
            for (std::size_t i = 0; i < 8; ++i) {
                const float f = v[i] == 0.0f ? 0.0f : v[i]; // -0 and +0 share a vertex
                std::memcpy(&key[i], &f, sizeof f);
            }
            const auto [it, inserted] = ids.emplace(key, static_cast<std::uint32_t>(prim.vertices.size()));
            if (inserted)
                prim.vertices.push_back(v);
            prim.indices.push_back(it->second);
        }
    }
    return prim;
}

// Accumulates the binary buffer with its views and accessors.
class BufferBuilder {
public:
    // Adds the attributes of a primitive; returns the glTF primitive object.
    nlohmann::json add(const Primitive& prim, int material) {
        std::array<float, 3> lo, hi;
        lo.fill(std::numeric_limits<float>::max());
        hi.fill(std::numeric_limits<float>::lowest());
        for (const auto& v : prim.vertices)
            for (std::size_t i = 0; i < 3; ++i) {
                lo[i] = std::min(lo[i], v[i]);
                hi[i] = std::max(hi[i], v[i]);
            }
        nlohmann::json attributes;
        const std::size_t count = prim.vertices.size();
        attributes["POSITION"] = accessor(view(prim, 0, 3, kArrayBuffer), count, "VEC3");
        accessors_.back()["min"] = lo;
        accessors_.back()["max"] = hi;
        attributes["NORMAL"] = accessor(view(prim, 3, 3, kArrayBuffer), count, "VEC3");
        attributes["TEXCOORD_0"] = accessor(view(prim, 6, 2, kArrayBuffer), count, "VEC2");
        const std::size_t begin = bytes_.size();
        for (std::uint32_t i : prim.indices)
            appendRaw(bytes_, i);
        const int indices = accessor(addView(begin, kElementArrayBuffer), prim.indices.size(), "SCALAR");
        accessors_.back()["componentType"] = kUnsignedInt;
        nlohmann::json primitive = {{"attributes", attributes}, {"indices", indices}, {"mode", 4}};
        if (material >= 0)
            primitive["material"] = material;
        return primitive;
    }

    const std::string& bytes() const { return bytes_; }
    const nlohmann::json& views() const { return views_; }
    const nlohmann::json& accessors() const { return accessors_; }

private:
    int view(const Primitive& prim, std::size_t first, std::size_t n, int target) {
        const std::size_t begin = bytes_.size();
        for (const auto& v : prim.vertices)
            for (std::size_t i = first; i < first + n; ++i)
                appendRaw(bytes_, v[i]);
        return addView(begin, target);
    }
    int addView(std::size_t begin, int target) {
        views_.push_back({{"buffer", 0},
                          {"byteOffset", begin},
                          {"byteLength", bytes_.size() - begin},
                          {"target", target}});
        return static_cast<int>(views_.size()) - 1;
    }
    int accessor(int view, std::size_t count, const char* type) {
        accessors_.push_back(
            {{"bufferView", view}, {"componentType", kFloat}, {"count", count}, {"type", type}});
        return static_cast<int>(accessors_.size()) - 1;
    }

    std::string bytes_;
    nlohmann::json views_ = nlohmann::json::array();
    nlohmann::json accessors_ = nlohmann::json::array();
};

// The glTF name of material id in mesh: "interior" for cut faces, else its name ("surface" when unnamed).
std::string materialName(const Mesh& mesh, std::uint32_t id) {
    if (id == kInteriorMaterial)
        return std::string(kInteriorMaterialName);
    if (id < mesh.materialNames.size() && !mesh.materialNames[id].empty())
        return mesh.materialNames[id];
    return mesh.materialNames.empty() ? "surface" : "material_" + std::to_string(id);
}

// The glTF materials (and their textures and images) in order of first use.
class MaterialTable {
public:
    MaterialTable(const std::vector<AssetMaterial>& defined, const std::filesystem::path& folder)
        : defined_(defined), textures_(folder) {}

    Result<int> index(const std::string& name) {
        if (const auto it = ids_.find(name); it != ids_.end())
            return it->second;
        const bool interior = name == kInteriorMaterialName;
        Vec3 colour = interior ? Vec3{0.85, 0.45, 0.2} : Vec3{0.8, 0.8, 0.8};
        nlohmann::json pbr = {{"metallicFactor", 0.0}, {"roughnessFactor", 0.9}};
        for (const AssetMaterial& m : defined_) {
            if (m.name != name)
                continue;
            colour = m.baseColor;
            for (const TextureMap& map : m.maps) {
                if (map.slot != "map_Kd")
                    continue;
                auto uri = textures_.place(map);
                if (!uri)
                    return uri.error();
                int image = -1;
                if (const auto it = images_.find(uri.value()); it != images_.end()) {
                    image = it->second;
                } else {
                    image = static_cast<int>(imagesJson_.size());
                    images_.emplace(uri.value(), image);
                    imagesJson_.push_back({{"uri", uri.value()}});
                    texturesJson_.push_back({{"source", image}, {"sampler", 0}});
                }
                pbr["baseColorTexture"] = {{"index", image}};
                colour = Vec3{1, 1, 1}; // the factor multiplies the image (MTL viewers show map_Kd as is)
                break;
            }
        }
        pbr["baseColorFactor"] = {colour.x, colour.y, colour.z, 1.0};
        materialsJson_.push_back({{"name", name}, {"pbrMetallicRoughness", pbr}});
        const int id = static_cast<int>(materialsJson_.size()) - 1;
        ids_.emplace(name, id);
        return id;
    }

    void store(nlohmann::json& doc) const {
        doc["materials"] = materialsJson_;
        if (!imagesJson_.empty()) {
            doc["images"] = imagesJson_;
            doc["textures"] = texturesJson_;
            doc["samplers"] = nlohmann::json::array({{{"wrapS", 10497}, {"wrapT", 10497}}});
        }
    }

private:
    const std::vector<AssetMaterial>& defined_;
    io::TextureFiles textures_;
    std::map<std::string, int> ids_;
    std::map<std::string, int> images_;
    nlohmann::json materialsJson_ = nlohmann::json::array();
    nlohmann::json imagesJson_ = nlohmann::json::array();
    nlohmann::json texturesJson_ = nlohmann::json::array();
};

Status checkMesh(const std::string& where, const std::string& name, const Mesh& mesh) {
    if (mesh.empty())
        return makeError(ErrorCode::InvalidInput, where + ": cannot write node '" + name + "': no triangles");
    if (Status s = mesh.validate(); !s)
        return makeError(ErrorCode::InvalidInput,
                         where + ": cannot write node '" + name + "': " + s.message());
    return {};
}

std::string partName(const std::string& node, std::size_t k) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "_hull_%02zu", k);
    return node + buf + "-convcolonly";
}

} // namespace

std::string pieceExtras(const MassProperties& mass, int level, const std::string& parent) {
    nlohmann::json inertia = nlohmann::json::array();
    for (int r = 0; r < 3; ++r)
        inertia.push_back({mass.inertia.m[r][0], mass.inertia.m[r][1], mass.inertia.m[r][2]});
    const Vec3& c = mass.centerOfMass;
    nlohmann::json j = {{"level", level},
                        {"density", 1.0},
                        {"mass", mass.volume},
                        {"volume", mass.volume},
                        {"center_of_mass", {c.x, c.y, c.z}},
                        {"inertia", inertia}};
    if (!parent.empty())
        j["parent"] = parent;
    return nlohmann::json{{"rubble", j}}.dump();
}

Status writeGltf(const std::filesystem::path& path, const std::vector<GltfNode>& nodes,
                 const std::vector<AssetMaterial>& materials, const std::string& sceneExtras) {
    const std::string where = io::displayName(path);
    if (nodes.empty())
        return makeError(ErrorCode::InvalidInput, where + ": cannot write a glTF file without nodes");
    BufferBuilder buffer;
    MaterialTable table(materials, path.has_parent_path() ? path.parent_path() : std::filesystem::path("."));
    nlohmann::json meshes = nlohmann::json::array();
    std::vector<nlohmann::json> gltfNodes(nodes.size());
    std::vector<nlohmann::json> extraNodes; // collision children, numbered after the pieces
    nlohmann::json sceneNodes = nlohmann::json::array();
    // A mesh with one primitive per material id (collision parts: one primitive without a material).
    auto addMesh = [&](const std::string& name, const Mesh& mesh, const Vec3& origin,
                       bool collision) -> Result<int> {
        std::set<std::uint32_t> ids;
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
            ids.insert(mesh.material(t));
        nlohmann::json primitives = nlohmann::json::array();
        for (const std::uint32_t id : ids) {
            int material = -1;
            if (!collision) {
                auto found = table.index(materialName(mesh, id));
                if (!found)
                    return found.error();
                material = found.value();
            }
            primitives.push_back(buffer.add(buildPrimitive(mesh, origin, id), material));
        }
        meshes.push_back({{"name", name}, {"primitives", primitives}});
        return static_cast<int>(meshes.size()) - 1;
    };
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const GltfNode& node = nodes[i];
        if (Status s = checkMesh(where, node.name, node.mesh); !s)
            return s;
        if (!isFinite(node.origin))
            return makeError(ErrorCode::InvalidInput,
                             where + ": cannot write node '" + node.name + "': origin is not finite");
        if (node.parent >= static_cast<int>(i))
            return makeError(ErrorCode::InvalidInput,
                             where + ": node '" + node.name + "': its parent must be written before it");
        const Vec3 base = node.parent >= 0 ? nodes[static_cast<std::size_t>(node.parent)].origin : Vec3{};
        const Vec3 t = node.origin - base;
        auto mesh = addMesh(node.name, node.mesh, node.origin, false);
        if (!mesh)
            return mesh.error();
        nlohmann::json& j = gltfNodes[i];
        j = {{"name", node.name}, {"mesh", mesh.value()}, {"translation", {t.x, t.y, t.z}}};
        if (!node.extras.empty()) {
            try {
                j["extras"] = nlohmann::json::parse(node.extras);
            } catch (const std::exception& e) {
                return makeError(ErrorCode::InvalidInput,
                                 where + ": node '" + node.name + "': extras are not JSON: " + e.what());
            }
        }
        nlohmann::json children = nlohmann::json::array();
        for (std::size_t k = 0; k < node.collision.size(); ++k) {
            const std::string name = partName(node.name, k);
            if (Status s = checkMesh(where, name, node.collision[k]); !s)
                return s;
            Mesh part = node.collision[k];
            part.materials.clear();
            part.materialNames.clear();
            auto partMesh = addMesh(name, part, node.origin, true);
            if (!partMesh)
                return partMesh.error();
            children.push_back(static_cast<int>(nodes.size() + extraNodes.size()));
            extraNodes.push_back({{"name", name}, {"mesh", partMesh.value()}});
        }
        for (std::size_t c = i + 1; c < nodes.size(); ++c)
            if (nodes[c].parent == static_cast<int>(i))
                children.push_back(static_cast<int>(c));
        if (!children.empty())
            j["children"] = children;
        if (node.parent < 0)
            sceneNodes.push_back(i);
    }
    nlohmann::json all = nlohmann::json::array();
    for (nlohmann::json& n : gltfNodes)
        all.push_back(std::move(n));
    for (nlohmann::json& n : extraNodes)
        all.push_back(std::move(n));
    nlohmann::json doc;
    doc["asset"] = {{"version", "2.0"}, {"generator", "Rubble"}};
    doc["scene"] = 0;
    doc["scenes"] = nlohmann::json::array({{{"nodes", sceneNodes}}});
    if (!sceneExtras.empty()) {
        try {
            doc["scenes"][0]["extras"] = nlohmann::json::parse(sceneExtras);
        } catch (const std::exception& e) {
            return makeError(ErrorCode::InvalidInput, where + ": scene extras are not JSON: " + e.what());
        }
    }
    doc["nodes"] = all;
    doc["meshes"] = meshes;
    table.store(doc);
    doc["buffers"] =
        nlohmann::json::array({{{"byteLength", buffer.bytes().size()},
                                {"uri", "data:application/octet-stream;base64," + base64(buffer.bytes())}}});
    doc["bufferViews"] = buffer.views();
    doc["accessors"] = buffer.accessors();
    const std::string text = doc.dump(1) + "\n";
    return io::writeFileAtomically(path, text);
}

} // namespace rubble
