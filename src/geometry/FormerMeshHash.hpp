#pragma once
// Private helper of the geometry module: Mesh::hash as it was before (inline: the bench times it too).

#include <bit>
#include <cstddef>
#include <cstdint>

#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// FNV-1a over the mesh's bytes, which a version-1 decomposition file names its mesh by.
inline std::uint64_t formerMeshHash(const Mesh& mesh) {
    std::uint64_t h = 1469598103934665603ull;
    auto bytes = [&h](const void* p, std::size_t n) {
        const auto* c = static_cast<const unsigned char*>(p);
        for (std::size_t i = 0; i < n; ++i) {
            h ^= c[i];
            h *= 1099511628211ull;
        }
    };
    auto u64 = [&](std::uint64_t v) { bytes(&v, sizeof v); };
    auto real = [&](double d) { u64(std::bit_cast<std::uint64_t>(d + 0.0)); };
    u64(mesh.positions.size());
    for (const Vec3& p : mesh.positions) {
        real(p.x);
        real(p.y);
        real(p.z);
    }
    u64(mesh.triangles.size());
    for (const Triangle& t : mesh.triangles)
        bytes(t.data(), sizeof(t));
    u64(mesh.normals.size());
    for (const Vec3f& n : mesh.normals) {
        real(n.x);
        real(n.y);
        real(n.z);
    }
    u64(mesh.uvs.size());
    for (const Vec2f& u : mesh.uvs) {
        real(u.x);
        real(u.y);
    }
    u64(mesh.materials.size());
    if (!mesh.materials.empty())
        bytes(mesh.materials.data(), mesh.materials.size() * sizeof(mesh.materials[0]));
    return h;
}

} // namespace rubble::detail
