// readMesh: OBJ, OFF, PLY and STL through Rubble's readers; 3DS and glTF through Assimp after checking size
// claims in their headers (Assimp trusts them and may try to allocate what a broken or hostile file claims).
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
#include "io/MeshFormatReaders.hpp"
#include "io/PolygonTriangulation.hpp"
#include "io/ReaderSupport.hpp"
#include "io/SceneReaders.hpp"
#include "io/TextTokens.hpp"
#include "io/TextureFiles.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/io/SceneIO.hpp"

namespace rubble {

namespace {
using detail::bytesText;
using detail::lower;
using detail::parseCount;
using detail::parseError;
using detail::readU16;
using detail::readU32;

// --- OFF --------------------------------------------------------------------------------------------------

Status guardOff(const std::string& b, const std::string& name) {
    // Tokens with their line numbers, comments skipped; only the first few are needed.
    std::vector<std::pair<std::string, std::size_t>> tok;
    std::size_t line = 1;
    const char br = detail::lineBreakOf(b);
    for (std::size_t i = 0; i < b.size() && tok.size() < 6;) {
        const char c = b[i];
        if (c == br) {
            ++line;
            ++i;
        } else if (c == '#') {
            while (i < b.size() && b[i] != br)
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
// Triangles of a glTF file once every node's mesh is copied into place (nodes instancing one mesh multiply
// it).
constexpr long double kMaxGltfInstancedTriangles = 1 << 24;

// The triangles a glTF file expands to: the triangles of each node's mesh, summed over the nodes (accessor
// counts already checked against their buffers).
long double gltfInstancedTriangles(const nlohmann::json& j) {
    using nlohmann::json;
    if (!j.contains("nodes") || !j["nodes"].is_array() || !j.contains("meshes") || !j["meshes"].is_array())
        return 0;
    const json* accessors = j.contains("accessors") && j["accessors"].is_array() ? &j["accessors"] : nullptr;
    auto accessorCount = [&](const json& index) -> long double {
        if (!accessors || !index.is_number_unsigned() || index.get<std::uint64_t>() >= accessors->size())
            return 0;
        const json& a = (*accessors)[index.get<std::size_t>()];
        return a.is_object() && a.contains("count") && a["count"].is_number() ? a["count"].get<long double>()
                                                                              : 0;
    };
    std::vector<long double> meshTriangles;
    for (const json& m : j["meshes"]) {
        long double t = 0;
        if (m.is_object() && m.contains("primitives") && m["primitives"].is_array())
            for (const json& p : m["primitives"]) {
                if (!p.is_object())
                    continue;
                long double n = 0;
                if (p.contains("indices"))
                    n = accessorCount(p["indices"]);
                else if (p.contains("attributes") && p["attributes"].is_object() &&
                         p["attributes"].contains("POSITION"))
                    n = accessorCount(p["attributes"]["POSITION"]);
                const long double mode =
                    p.contains("mode") && p["mode"].is_number() ? p["mode"].get<long double>() : 4;
                t += mode == 4 ? n / 3 : mode == 5 || mode == 6 ? std::max(n - 2, 0.0L) : 0;
            }
        meshTriangles.push_back(t);
    }
    long double total = 0;
    for (const json& node : j["nodes"])
        if (node.is_object() && node.contains("mesh") && node["mesh"].is_number_unsigned() &&
            node["mesh"].get<std::uint64_t>() < meshTriangles.size())
            total += meshTriangles[node["mesh"].get<std::size_t>()];
    return total;
}

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
    if (const long double triangles = gltfInstancedTriangles(j); triangles > kMaxGltfInstancedTriangles)
        return parseError(name, "its nodes place " + bytesText(triangles) +
                                    " triangles (every node a copy of its mesh), more than the limit of " +
                                    bytesText(kMaxGltfInstancedTriangles));
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

Status importWithAssimp(AssimpScene& out, const std::filesystem::path& path, const std::string& name) {
    out.importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    try {
        // Polygons are triangulated below, not by aiProcess_Triangulate: Debian's Assimp is built with its
        // assertions on, and TriangulateProcess aborts the process on some malformed polygons.
        const unsigned flags = aiProcess_ValidateDataStructure | aiProcess_JoinIdenticalVertices;
        out.scene = out.importer.ReadFile(path.string(), flags);
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
                tri[c] = weld_.add({p.x, p.y, p.z});
            }
            if (!ok)
                continue;
            m_.triangles.push_back(tri);
            if (anyNormals_) {
                for (int c = 0; c < 3; ++c) {
                    if (am->HasNormals()) {
                        const aiVector3D n = normalXf * am->mNormals[ids[c]];
                        m_.normals.emplace_back(normalized(Vec3{n.x, n.y, n.z}));
                    } else {
                        m_.normals.emplace_back(normalized(m_.triangleNormal(m_.triangles.size() - 1)));
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
    detail::PositionWelder weld_{m_};
};

std::string nodeName(const aiNode* node) {
    return node->mName.C_Str();
}

Result<Mesh> readWithAssimp(const std::filesystem::path& path, const std::string& name) {
    AssimpScene imported;
    if (Status s = importWithAssimp(imported, path, name); !s)
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
            } else if (!uri.empty() && !io::refuseAbsoluteImage(mat.name, uri, out.warnings)) {
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
    if (Status s = importWithAssimp(imported, path, name); !s)
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
        if (ext == ".stl")
            return io::parseStl(b, name);
        if (ext == ".ply")
            return io::parsePly(b, name);
        if (ext == ".3ds")
            guard = guard3ds(b, name);
        else
            guard = guardGltf(b, path, name, ext == ".glb");
    }
    if (!guard)
        return guard.error();
    return readWithAssimp(path, name);
}

} // namespace rubble
