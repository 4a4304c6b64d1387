// Fuzz target: the OFF parser, then check and repair of whatever it produced.
#include <cstdint>
#include <string_view>

#include "FuzzChecks.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/geometry/MeshRepair.hpp"
#include "rubble/io/MeshIO.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto mesh = rubble::parseOff(text, "fuzz.off");
    if (!mesh) {
        if (mesh.error().message.rfind("fuzz.off", 0) != 0)
            __builtin_trap(); // errors must name the file
        return 0;
    }
    if (!rubble::fuzz::structurallyValid(*mesh) || mesh->triangleCount() == 0)
        __builtin_trap();
    for (std::size_t v = 0; v < mesh->positions.size(); ++v) { // unreferenced vertices are dropped
        bool used = false;
        for (const rubble::Triangle& t : mesh->triangles)
            used = used || t[0] == v || t[1] == v || t[2] == v;
        if (!used)
            __builtin_trap();
    }
    rubble::CheckOptions options;
    options.selfIntersections = mesh->triangleCount() < 2000;
    (void)rubble::checkMesh(*mesh, options);
    rubble::Mesh copy = *mesh;
    rubble::RepairOptions repair;
    repair.checkSelfIntersections = options.selfIntersections;
    (void)rubble::repairMesh(copy, repair);
    return 0;
}
