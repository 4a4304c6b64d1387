// Fuzz target: check and repair of small arbitrary triangle soups (bad indices, NaN, duplicates, flips).
#include <cstdint>

#include "FuzzInput.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/geometry/MeshRepair.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    rubble::fuzz::FuzzInput in(data, size);
    rubble::Mesh mesh;
    const int vertices = in.byte() % 24;
    for (int i = 0; i < vertices; ++i)
        mesh.positions.push_back({in.coordinate(), in.coordinate(), in.coordinate()});
    while (in.more() && mesh.triangles.size() < 64) {
        // Indices may point past the vertices on purpose.
        const auto a = in.byte() % (vertices + 2), b = in.byte() % (vertices + 2),
                   c = in.byte() % (vertices + 2);
        mesh.triangles.push_back(
            {static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b), static_cast<std::uint32_t>(c)});
    }
    const rubble::MeshReport before = rubble::checkMesh(mesh);
    if (before.valid() && !mesh.validate().isOk())
        __builtin_trap();
    rubble::Mesh repaired = mesh;
    const rubble::RepairReport report = rubble::repairMesh(repaired);
    // The report's final check must describe the repaired mesh, and a valid result must be structurally
    // sound.
    if (report.after.valid() != rubble::checkMesh(repaired).valid())
        __builtin_trap();
    if (report.after.valid() && !repaired.validate().isOk())
        __builtin_trap();
    // Repair is idempotent on valid results.
    if (report.after.valid()) {
        rubble::Mesh again = repaired;
        const rubble::RepairReport second = rubble::repairMesh(again);
        if (!second.after.valid())
            __builtin_trap();
    }
    return 0;
}
