// Fuzz target: Rubble's PLY and STL readers (ASCII and binary) (first byte even: PLY, odd: STL; the rest is
// the file), then check and repair of whatever they produced.
#include <cstdint>
#include <string>

#include "FuzzChecks.hpp"
#include "io/MeshFormatReaders.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/geometry/MeshRepair.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0)
        return 0;
    const bool ply = data[0] % 2 == 0;
    const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
    const std::string name = ply ? "fuzz.ply" : "fuzz.stl";
    auto mesh = ply ? rubble::io::parsePly(text, name) : rubble::io::parseStl(text, name);
    if (!mesh) {
        if (mesh.error().message.rfind(name, 0) != 0)
            __builtin_trap(); // errors must name the file
        return 0;
    }
    if (!rubble::fuzz::structurallyValid(*mesh) || mesh->triangleCount() == 0)
        __builtin_trap();
    rubble::CheckOptions options;
    options.selfIntersections = mesh->triangleCount() < 2000;
    (void)rubble::checkMesh(*mesh, options);
    rubble::Mesh copy = *mesh;
    rubble::RepairOptions repair;
    repair.checkSelfIntersections = options.selfIntersections;
    (void)rubble::repairMesh(copy, repair);
    return 0;
}
