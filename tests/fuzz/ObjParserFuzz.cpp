// Fuzz target: the OBJ parser, then check and repair of whatever it produced.
#include <cstdint>
#include <string_view>

#include "FuzzChecks.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/geometry/MeshRepair.hpp"
#include "rubble/io/MeshIO.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto mesh = rubble::parseObj(text, "fuzz.obj");
    if (!mesh) {
        // Errors must name the file.
        if (mesh.error().message.rfind("fuzz.obj", 0) != 0)
            __builtin_trap();
        return 0;
    }
    if (!rubble::fuzz::structurallyValid(*mesh))
        __builtin_trap(); // the parser must only produce structurally valid meshes (NaN is check's business)
    rubble::CheckOptions options;
    options.selfIntersections = mesh->triangleCount() < 2000;
    (void)rubble::checkMesh(*mesh, options);
    rubble::Mesh copy = *mesh;
    rubble::RepairOptions repair;
    repair.checkSelfIntersections = options.selfIntersections;
    (void)rubble::repairMesh(copy, repair);
    return 0;
}
