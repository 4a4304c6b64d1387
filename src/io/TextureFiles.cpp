// Texture images copied next to written OBJ/MTL and glTF files.
#include "io/TextureFiles.hpp"

#include "io/FileBytes.hpp"

namespace rubble::io {

namespace {
// FNV-1a of embedded image bytes (names their file).
std::uint64_t fnv1a(const std::string& bytes) {
    std::uint64_t h = 1469598103934665603ull;
    for (const char c : bytes) {
        h ^= static_cast<unsigned char>(c);
        h *= 1099511628211ull;
    }
    return h;
}
} // namespace

bool refuseAbsoluteImage(const std::string& material, const std::filesystem::path& image,
                         std::vector<std::string>& warnings) {
    if (!image.is_absolute())
        return false;
    warnings.push_back(
        "material '" + material + "': image " + image.string() +
        " is named by an absolute path: not used (images are copied only from paths relative to "
        "the model's folder)");
    return true;
}

Result<std::string> TextureFiles::place(const TextureMap& map) {
    namespace fs = std::filesystem;
    const bool embedded = map.file.empty();
    const std::string key = embedded ? "embedded:" + std::to_string(fnv1a(map.bytes)) + map.extension
                                     : "file:" + map.file.string();
    if (const auto it = placed_.find(key); it != placed_.end())
        return it->second;
    std::string bytes;
    std::string name;
    if (embedded) {
        bytes = map.bytes;
        char buf[32];
        std::snprintf(buf, sizeof buf, "image_%016llx", static_cast<unsigned long long>(fnv1a(map.bytes)));
        name = buf + map.extension;
    } else {
        auto read = readFileBytes(map.file);
        if (!read) { // referenced where it is (relative to the output), not copied
            std::error_code ec;
            const fs::path from = fs::absolute(folder_, ec);
            const fs::path to = fs::absolute(map.file, ec);
            const std::string uri = to.lexically_relative(from).generic_string();
            placed_.emplace(key, uri.empty() ? to.generic_string() : uri);
            return placed_[key];
        }
        bytes = std::move(read.value());
        name = map.file.filename().string();
    }
    // Two images of the same file name from different folders: the second becomes stem_2.ext, ...
    const fs::path base(name);
    for (int n = 2; names_.count(name) > 0; ++n)
        name = base.stem().string() + "_" + std::to_string(n) + base.extension().string();
    names_.insert(name);
    const fs::path target = folder_ / "textures" / name;
    std::error_code ec;
    fs::create_directories(target.parent_path(), ec);
    if (ec)
        return makeError(ErrorCode::IoError,
                         displayName(target.parent_path()) + ": cannot create: " + ec.message());
    if (!(fs::exists(target, ec) && fs::file_size(target, ec) == bytes.size()))
        if (Status s = writeFileAtomically(target, bytes); !s)
            return s.error();
    const std::string uri = "textures/" + name;
    placed_.emplace(key, uri);
    return uri;
}

} // namespace rubble::io
