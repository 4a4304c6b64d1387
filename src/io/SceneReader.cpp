// readScene: multi-object files as objects with their collision parts and materials; MTL parsing.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>

#include "io/FileBytes.hpp"
#include "io/SceneReaders.hpp"
#include "io/TextTokens.hpp"
#include "io/TextureFiles.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/io/SceneIO.hpp"

namespace rubble {

namespace {

std::string lower(std::string s) {
    for (char& c : s)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

bool endsWith(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
        s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
        s.remove_suffix(1);
    return s;
}

// MTL statements whose last argument is an image file.
bool isMapStatement(const std::string& key) {
    return key.rfind("map_", 0) == 0 || key == "bump" || key == "disp" || key == "decal" || key == "refl" ||
           key == "norm";
}

// Splits "-o 1 1 1 -s 2 2 2 file name.png" into options and a file: options are '-' tokens with their numeric
// arguments, the rest is the file (which may contain spaces).
void splitMapArguments(std::string_view rest, std::string& options, std::string& file) {
    std::size_t at = 0;
    auto skipSpaces = [&] {
        while (at < rest.size() && (rest[at] == ' ' || rest[at] == '\t'))
            ++at;
    };
    auto token = [&] {
        const std::size_t b = at;
        while (at < rest.size() && rest[at] != ' ' && rest[at] != '\t')
            ++at;
        return rest.substr(b, at - b);
    };
    auto isNumberOrFlag = [](std::string_view t) {
        if (t == "on" || t == "off")
            return true;
        double v = 0;
        const auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        return ec == std::errc() && p == t.data() + t.size();
    };
    skipSpaces();
    std::size_t fileStart = at;
    while (at < rest.size() && rest[at] == '-') {
        token();
        skipSpaces();
        std::size_t mark = at;
        while (at < rest.size()) {
            const std::string_view t = token();
            if (!isNumberOrFlag(t)) {
                at = mark;
                break;
            }
            skipSpaces();
            mark = at;
        }
        fileStart = at;
    }
    options = std::string(trim(rest.substr(0, fileStart)));
    file = std::string(trim(rest.substr(fileStart)));
}

// An OBJ file as a scene: objects, UCX_ parts attached to their object, materials from its mtllib files.
Result<AssetScene> readObjScene(const std::filesystem::path& path) {
    auto bytes = io::readFileBytes(path);
    if (!bytes)
        return bytes.error();
    const std::string name = io::displayName(path);
    const std::string& text = bytes.value();
    // Objects are `o` statements; a file without any is one object (its `g` groups usually split one solid).
    bool hasO = false;
    const char br = detail::lineBreakOf(text);
    for (std::size_t at = 0; at < text.size() && !hasO;) {
        std::size_t end = text.find(br, at);
        if (end == std::string::npos)
            end = text.size();
        const std::string_view line = trim(std::string_view(text).substr(at, end - at));
        hasO = line.size() > 1 && line[0] == 'o' && (line[1] == ' ' || line[1] == '\t');
        at = end + 1;
    }
    Result<std::vector<NamedMesh>> objects = std::vector<NamedMesh>{};
    if (hasO) {
        objects = parseObjObjects(text, name);
    } else if (auto merged = parseObj(text, name)) {
        objects.value().push_back({path.stem().string(), std::move(merged.value())});
    } else {
        return merged.error();
    }
    if (!objects)
        return objects.error();
    AssetScene scene;
    std::map<std::string, std::size_t> byName;
    std::vector<std::pair<std::string, Mesh>> parts; // UCX_ objects, attached once every object is known
    for (NamedMesh& nm : objects.value()) {
        if (isCollisionName(nm.name)) {
            parts.emplace_back(nm.name, std::move(nm.mesh));
            continue;
        }
        byName.emplace(nm.name, scene.objects.size());
        scene.objects.push_back({nm.name, std::move(nm.mesh), {}, -1});
    }
    for (auto& [partName, mesh] : parts) {
        // UCX_<object>_<n>: the longest object name that fits.
        std::string owner = partName.substr(4);
        const auto cut = owner.rfind('_');
        if (cut != std::string::npos)
            owner.resize(cut);
        const auto it = byName.find(owner);
        if (it == byName.end()) {
            scene.warnings.push_back(name + ": collision object '" + partName + "' names no object '" +
                                     owner + "'");
            continue;
        }
        mesh.materials.clear();
        mesh.materialNames.clear();
        scene.objects[it->second].collision.push_back(std::move(mesh));
    }
    if (scene.objects.empty())
        return makeError(ErrorCode::ParseError, name + ": no triangles outside collision objects");

    // Materials of every mtllib statement.
    std::size_t at = 0;
    while (at < text.size()) {
        std::size_t end = text.find(br, at);
        if (end == std::string::npos)
            end = text.size();
        const std::string_view line = trim(std::string_view(text).substr(at, end - at));
        at = end + 1;
        if (line.rfind("mtllib", 0) != 0 || line.size() < 7 || (line[6] != ' ' && line[6] != '\t'))
            continue;
        const std::filesystem::path mtl = path.parent_path() / std::string(trim(line.substr(6)));
        auto mtlBytes = io::readFileBytes(mtl);
        if (!mtlBytes) {
            scene.warnings.push_back(mtlBytes.error().message);
            continue;
        }
        auto mats = parseMtl(mtlBytes.value(), io::displayName(mtl), {}); // image paths as written
        if (!mats) { // as a missing one: the geometry does not depend on it
            scene.warnings.push_back(mats.error().message + " (its materials are not used)");
            continue;
        }
        for (AssetMaterial& m : mats.value()) {
            std::erase_if(m.maps, [&](const TextureMap& map) {
                return io::refuseAbsoluteImage(m.name, map.file, scene.warnings);
            });
            for (TextureMap& map : m.maps)
                map.file = (mtl.parent_path() / map.file).lexically_normal();
            scene.materials.push_back(std::move(m));
        }
    }
    for (const AssetMaterial& m : scene.materials)
        for (const TextureMap& map : m.maps) {
            std::error_code ec;
            if (!map.file.empty() && !std::filesystem::exists(map.file, ec))
                scene.warnings.push_back("material '" + m.name + "': image " + map.file.string() +
                                         " not found");
        }
    return scene;
}

} // namespace

bool isCollisionName(const std::string& name) {
    const std::string l = lower(name);
    return l.rfind("ucx_", 0) == 0 || endsWith(l, "-colonly") || endsWith(l, "-convcolonly");
}

Result<std::vector<AssetMaterial>> parseMtl(std::string_view text, const std::string& displayName,
                                            const std::filesystem::path& folder) {
    std::vector<AssetMaterial> out;
    std::size_t at = 0;
    std::size_t lineNo = 0;
    const char br = detail::lineBreakOf(text);
    while (at < text.size()) {
        std::size_t end = text.find(br, at);
        if (end == std::string_view::npos)
            end = text.size();
        const std::string_view line = trim(text.substr(at, end - at));
        at = end + 1;
        ++lineNo;
        if (line.empty() || line.front() == '#')
            continue;
        std::size_t k = 0;
        while (k < line.size() && line[k] != ' ' && line[k] != '\t')
            ++k;
        const std::string key(line.substr(0, k));
        const std::string_view rest = trim(line.substr(k));
        const std::string where = displayName + ":" + std::to_string(lineNo);
        if (key == "newmtl") {
            if (rest.empty())
                return makeError(ErrorCode::ParseError, where + ": newmtl without a name");
            out.push_back({});
            out.back().name = std::string(rest);
            continue;
        }
        if (out.empty())
            return makeError(ErrorCode::ParseError, where + ": '" + key + "' before the first newmtl");
        AssetMaterial& m = out.back();
        if (key == "Kd") {
            double c[3] = {0, 0, 0};
            std::size_t p = 0;
            int n = 0;
            for (; n < 3; ++n) {
                while (p < rest.size() && (rest[p] == ' ' || rest[p] == '\t'))
                    ++p;
                const auto [q, ec] = std::from_chars(rest.data() + p, rest.data() + rest.size(), c[n]);
                if (ec != std::errc())
                    break;
                p = static_cast<std::size_t>(q - rest.data());
            }
            if (n == 0)
                return makeError(ErrorCode::ParseError,
                                 where + ": Kd needs a colour, got '" + std::string(rest) + "'");
            if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2]))
                return makeError(ErrorCode::ParseError,
                                 where + ": Kd needs finite numbers, got '" + std::string(rest) + "'");
            m.baseColor = n == 3 ? Vec3{c[0], c[1], c[2]} : Vec3{c[0], c[0], c[0]};
        } else if (isMapStatement(key)) {
            TextureMap map;
            map.slot = key;
            std::string file;
            splitMapArguments(rest, map.options, file);
            if (file.empty())
                return makeError(ErrorCode::ParseError, where + ": " + key + " without a file name");
            std::replace(file.begin(), file.end(), '\\', '/');
            map.file = (folder / file).lexically_normal();
            m.maps.push_back(std::move(map));
        } else {
            m.statements.emplace_back(line);
        }
    }
    return out;
}

Result<AssetScene> readScene(const std::filesystem::path& path) {
    const std::string ext = lower(path.extension().string());
    if (ext == ".obj")
        return readObjScene(path);
    if (ext == ".gltf" || ext == ".glb")
        return io::readGltfScene(path);
    auto mesh = readMesh(path);
    if (!mesh)
        return mesh.error();
    AssetScene scene;
    scene.objects.push_back({path.stem().string(), std::move(mesh.value()), {}, -1});
    return scene;
}

} // namespace rubble
