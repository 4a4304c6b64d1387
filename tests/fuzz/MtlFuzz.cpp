// Fuzz target: the MTL parser (materials of OBJ scenes, carried into written OBJ and glTF files).
#include <cmath>
#include <cstdint>
#include <string_view>

#include "rubble/io/SceneIO.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto materials = rubble::parseMtl(text, "fuzz.mtl", "textures");
    if (!materials) {
        if (materials.error().message.rfind("fuzz.mtl:", 0) != 0)
            __builtin_trap(); // errors name the file and the line
        return 0;
    }
    for (const rubble::AssetMaterial& m : *materials) {
        if (m.name.empty())
            __builtin_trap();
        if (!std::isfinite(m.baseColor.x) || !std::isfinite(m.baseColor.y) || !std::isfinite(m.baseColor.z))
            __builtin_trap(); // writers put it in glTF JSON and MTL text
        for (const rubble::TextureMap& map : m.maps)
            if (map.file.empty() || map.slot.empty())
                __builtin_trap();
    }
    return 0;
}
