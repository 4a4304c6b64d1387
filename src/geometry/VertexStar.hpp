#pragma once
// Private to the core: the outgoing half-edges of every vertex of a triangle mesh in compressed (CSR) form,
// built in two linear passes without hashing. Half-edge h = 3·t + c runs from triangles[t][c] to
// triangles[t][(c + 1) % 3]. Edge queries scan one vertex's star (a handful of entries on real meshes).

#include <cstdint>
#include <vector>

#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// Outgoing half-edges per vertex. Requires every triangle index < mesh.positions.size().
class VertexStar {
public:
    /// Builds the stars of all vertices of mesh.
    explicit VertexStar(const Mesh& mesh) {
        const std::size_t nv = mesh.positions.size();
        first_.assign(nv + 1, 0);
        for (const Triangle& t : mesh.triangles)
            for (const std::uint32_t v : t)
                ++first_[v + 1];
        for (std::size_t v = 0; v < nv; ++v)
            first_[v + 1] += first_[v];
        to_.resize(3 * mesh.triangles.size());
        half_.resize(to_.size());
        std::vector<std::uint32_t> fill(first_.begin(), first_.end() - 1);
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
            for (std::uint32_t c = 0; c < 3; ++c) {
                const std::uint32_t a = mesh.triangles[t][c];
                const std::uint32_t slot = fill[a]++;
                to_[slot] = mesh.triangles[t][(c + 1) % 3];
                half_[slot] = static_cast<std::uint32_t>(3 * t + c);
            }
    }

    /// Index range [begin(v), end(v)) of v's outgoing half-edges in target() / halfEdge().
    std::uint32_t begin(std::uint32_t v) const { return first_[v]; }
    /// See begin().
    std::uint32_t end(std::uint32_t v) const { return first_[v + 1]; }
    /// Target vertex of the i-th stored half-edge.
    std::uint32_t target(std::uint32_t i) const { return to_[i]; }
    /// Half-edge id (3·triangle + corner) of the i-th stored half-edge.
    std::uint32_t halfEdge(std::uint32_t i) const { return half_[i]; }
    /// Number of vertices.
    std::uint32_t vertexCount() const { return static_cast<std::uint32_t>(first_.size() - 1); }

private:
    std::vector<std::uint32_t> first_, to_, half_;
};

} // namespace rubble::detail
