// Fuzz target: the world.cfg parser.
#include <cstdint>
#include <string>

#include "rubble/io/SceneConfig.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    auto scene = rubble::parseSceneConfigText(text, "fuzz.cfg", "/nonexistent-rubble-fuzz");
    if (!scene && scene.error().message.rfind("fuzz.cfg", 0) != 0)
        __builtin_trap(); // errors must name the file
    return 0;
}
