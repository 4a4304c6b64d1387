#include "TestSupport.hpp"

#include <cstdlib>
#include <fstream>

namespace rubble::test {

std::filesystem::path sourceDir() {
    return RUBBLE_SOURCE_DIR;
}

std::filesystem::path tempDir(const std::string& name) {
    const auto dir = std::filesystem::path(RUBBLE_BINARY_DIR) / "test-tmp" / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

std::optional<std::filesystem::path> seedMediaDir() {
    if (const char* env = std::getenv("RUBBLE_SEED_MEDIA"))
        if (std::filesystem::is_directory(env))
            return std::filesystem::path(env);
    for (const auto& candidate : {sourceDir() / ".." / "shared" / "seed" / "media",
                                  sourceDir() / ".." / ".." / "shared" / "seed" / "media"}) {
        if (std::filesystem::is_directory(candidate))
            return std::filesystem::canonical(candidate);
    }
    return std::nullopt;
}

std::filesystem::path writeFile(const std::filesystem::path& path, const std::string& text) {
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

} // namespace rubble::test
