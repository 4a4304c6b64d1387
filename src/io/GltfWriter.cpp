// glTF 2.0 writer: one node per mesh, two materials (surface, interior), one embedded base64 buffer.
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>

#include <nlohmann/json.hpp>

#include "io/FileBytes.hpp"
#include "rubble/MeshIO.hpp"

namespace rubble {

namespace {

constexpr int kFloat = 5126;
constexpr int kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;
constexpr int kSurface = 0;  // material index of ordinary faces
constexpr int kInterior = 1; // material index of cut faces

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

Primitive buildPrimitive(const Mesh& mesh, const Vec3& origin, bool interior) {
    Primitive prim;
    std::map<std::array<std::uint32_t, 8>, std::uint32_t> ids; // by bit pattern
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        if ((mesh.material(t) == kInteriorMaterial) != interior)
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
        return {{"attributes", attributes}, {"indices", indices}, {"material", material}, {"mode", 4}};
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

nlohmann::json material(const char* name, double r, double g, double b) {
    return {{"name", name},
            {"pbrMetallicRoughness",
             {{"baseColorFactor", {r, g, b, 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.9}}}};
}

} // namespace

Status writeGltf(const std::filesystem::path& path, const std::vector<GltfNode>& nodes) {
    const std::string where = io::displayName(path);
    if (nodes.empty())
        return makeError(ErrorCode::InvalidInput, where + ": cannot write a glTF file without nodes");
    BufferBuilder buffer;
    nlohmann::json meshes = nlohmann::json::array();
    nlohmann::json gltfNodes = nlohmann::json::array();
    nlohmann::json sceneNodes = nlohmann::json::array();
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const GltfNode& node = nodes[i];
        if (node.mesh.empty())
            return makeError(ErrorCode::InvalidInput,
                             where + ": cannot write node '" + node.name + "': no triangles");
        if (Status s = node.mesh.validate(); !s)
            return makeError(ErrorCode::InvalidInput,
                             where + ": cannot write node '" + node.name + "': " + s.message());
        if (!isFinite(node.origin))
            return makeError(ErrorCode::InvalidInput,
                             where + ": cannot write node '" + node.name + "': origin is not finite");
        nlohmann::json primitives = nlohmann::json::array();
        for (const bool interior : {false, true}) {
            const Primitive prim = buildPrimitive(node.mesh, node.origin, interior);
            if (!prim.indices.empty())
                primitives.push_back(buffer.add(prim, interior ? kInterior : kSurface));
        }
        meshes.push_back({{"name", node.name}, {"primitives", primitives}});
        gltfNodes.push_back({{"name", node.name},
                             {"mesh", i},
                             {"translation", {node.origin.x, node.origin.y, node.origin.z}}});
        sceneNodes.push_back(i);
    }
    nlohmann::json doc;
    doc["asset"] = {{"version", "2.0"}, {"generator", "Rubble"}};
    doc["scene"] = 0;
    doc["scenes"] = nlohmann::json::array({{{"nodes", sceneNodes}}});
    doc["nodes"] = gltfNodes;
    doc["meshes"] = meshes;
    doc["materials"] = {material("surface", 0.8, 0.8, 0.8), material("interior", 0.85, 0.45, 0.2)};
    doc["buffers"] =
        nlohmann::json::array({{{"byteLength", buffer.bytes().size()},
                                {"uri", "data:application/octet-stream;base64," + base64(buffer.bytes())}}});
    doc["bufferViews"] = buffer.views();
    doc["accessors"] = buffer.accessors();
    const std::string text = doc.dump(1) + "\n";
    return io::writeFileAtomically(path, text);
}

} // namespace rubble
