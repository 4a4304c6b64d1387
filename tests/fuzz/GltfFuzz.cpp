// Fuzz target: the glTF and GLB readers (the size-claim guard, then Assimp) as a mesh and as a scene. Byte 0
// picks the form (bit 0: GLB, bit 1: scene); the rest is the file, written to a per-process folder.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "FuzzChecks.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/io/SceneIO.hpp"

namespace {
// The per-process folder, removed when the process exits normally.
struct Folder {
    std::filesystem::path dir;
    Folder() {
        char pid[16]; // zero-padded: every run's paths, and so its messages, have the same length
        std::snprintf(pid, sizeof pid, "%010d", static_cast<int>(::getpid()));
        dir = std::filesystem::path("/tmp") / (std::string("rubble-fuzz-gltf-") + pid);
        std::filesystem::create_directories(dir);
    }
    Folder(const Folder&) = delete;
    Folder& operator=(const Folder&) = delete;
    ~Folder() {
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
    }
};

const std::filesystem::path& folder() {
    static const Folder f;
    return f.dir;
}

// A parsed mesh must be structurally sound; the error of a refused one must name the file.
template <class R>
void checkOutcome(const R& r, const std::string& name) {
    if (!r && r.error().message.find(name) == std::string::npos)
        __builtin_trap();
}
} // namespace

// Assimp's glTF importer leaks a buffer on some malformed files; the leak is theirs and bounded per file.
extern "C" const char* __lsan_default_suppressions() {
    return "leak:libassimp.so\n";
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0)
        return 0;
    const bool glb = data[0] & 1, scene = data[0] & 2;
    const std::string name = glb ? "fuzz.glb" : "fuzz.gltf";
    const std::filesystem::path path = folder() / name;
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
    }
    if (scene) {
        auto s = rubble::readScene(path);
        checkOutcome(s, name);
        if (s)
            for (const rubble::AssetObject& o : s->objects)
                if (!rubble::fuzz::structurallyValid(o.mesh))
                    __builtin_trap();
    } else {
        auto m = rubble::readMesh(path);
        checkOutcome(m, name);
        if (m && (!rubble::fuzz::structurallyValid(*m) || m->triangleCount() == 0))
            __builtin_trap();
    }
    return 0;
}
