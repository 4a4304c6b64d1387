// Fuzz target: the CLI's JSON output of arbitrary paths and reader messages (non-UTF-8 bytes included).
// Input: one byte n, then n % 64 bytes of file name, then the file's text (read as OFF when n >= 128, else
// OBJ).
#include <cstdint>
#include <string>
#include <string_view>

#include "JsonText.hpp"
#include "rubble/io/MeshIO.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0)
        return 0;
    const std::size_t n = std::min<std::size_t>(data[0] % 64, size - 1);
    const std::string path(reinterpret_cast<const char*>(data + 1), n);
    const std::string_view text(reinterpret_cast<const char*>(data + 1 + n), size - 1 - n);
    nlohmann::json entry = {{"file", rubble::tools::utf8Escaped(path)}};
    auto mesh = data[0] >= 128 ? rubble::parseOff(text, path) : rubble::parseObj(text, path);
    if (mesh)
        entry["triangles"] = mesh->triangleCount();
    else
        entry["error"] = rubble::tools::utf8Escaped(mesh.error().message);
    const nlohmann::json doc = {{"meshes", {entry}}};
    std::string out;
    try {
        out = doc.dump(); // strict: throws on any byte that is not UTF-8
    } catch (const nlohmann::json::exception&) {
        __builtin_trap();
    }
    if (rubble::tools::dumpJson(doc) != out)
        __builtin_trap(); // the safety net changes nothing in escaped text
    const nlohmann::json back = nlohmann::json::parse(out, nullptr, false);
    if (back.is_discarded() || back["meshes"][0]["file"] != rubble::tools::utf8Escaped(path))
        __builtin_trap();
    if (rubble::tools::utf8Escaped(path) == path && back["meshes"][0]["file"] != path)
        __builtin_trap(); // valid UTF-8 names are kept as they are
    return 0;
}
